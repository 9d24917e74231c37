// Tests of the cancellation points (solvers/cancel.h): with a cancellation
// requested, every long computation of factor/ throws Cancelled and returns
// nothing; once it is withdrawn, the same call gives exactly the result of a
// call that never saw one (a check only reads the flag).
#include <stdexcept>
#include <type_traits>

#include "brdfs/catalogue.h"
#include "brdfs/sampleset.h"
#include "factor/homomorphic_fit.h"
#include "factor/model_fit.h"
#include "factor/refine.h"
#include "factor/sh_baseline.h"
#include "factor/svd_baseline.h"
#include "solvers/cancel.h"
#include "test_common.h"

using namespace bf;

namespace {

// Requests a cancellation for its lifetime.
struct CancelRequested {
  CancelRequested() { request_cancel(); }
  ~CancelRequested() { clear_cancel(); }
};

}  // namespace

TEST_CASE("cancel: a cancellation is not a runtime_error, so recovering code does not swallow it") {
  STATIC_REQUIRE(!std::is_base_of_v<std::runtime_error, Cancelled>);
  STATIC_REQUIRE(std::is_base_of_v<std::exception, Cancelled>);
  REQUIRE_FALSE(cancel_requested());
  REQUIRE_NOTHROW(check_cancel());
  {
    CancelRequested c;
    REQUIRE(cancel_requested());
    REQUIRE_THROWS_AS(check_cancel(), Cancelled);
  }
  REQUIRE_FALSE(cancel_requested());
}

TEST_CASE("cancel: fits, tabulations and Ceres solves stop when asked and are unchanged otherwise") {
  const BrdfPtr b = Catalogue::builtin().make("bluepaint");
  const SampleSet s = sample_grid(*b, 6);
  const FitData d(s, 1e-5);
  const FitOptions fo;
  SvdOptions so;
  so.res = 8;
  ShkOptions ko;
  ko.order = 4;
  ko.view_res = 8;
  ShrOptions ro;
  ro.order = 4;
  ro.view_order = 2;
  RefineOptions rf;
  rf.max_iterations = 3;
  rf.threads = 1;
  ModelFitOptions mo;
  mo.model = "ward";
  mo.starts = 1;
  mo.threads = 1;

  const auto fit = fit_homomorphic(d, mccool_terms(6), fo, "mccool");
  const auto svd = fit_svd(*b, so);
  const auto shk = fit_shk(*b, ko);
  const auto shr = fit_shr(*b, ro);
  const auto refined = refine(*fit, s, rf);
  const ModelFitResult model = fit_model(s, mo);
  {
    CancelRequested c;
    CHECK_THROWS_AS(fit_homomorphic(d, mccool_terms(6), fo, "mccool"), Cancelled);
    CHECK_THROWS_AS(fit_svd(*b, so), Cancelled);
    CHECK_THROWS_AS(fit_shk(*b, ko), Cancelled);
    CHECK_THROWS_AS(fit_shr(*b, ro), Cancelled);
    CHECK_THROWS_AS(refine(*fit, s, rf), Cancelled);
    CHECK_THROWS_AS(fit_model(s, mo), Cancelled);
  }
  // Withdrawn: the same results, bit for bit.
  const Vec3 wi = Vec3(0.3, 0.1, 0.9).normalized(), wo = Vec3(-0.2, 0.4, 0.8).normalized();
  CHECK((fit_homomorphic(d, mccool_terms(6), fo, "mccool")->eval(wi, wo) == fit->eval(wi, wo)).all());
  CHECK((fit_svd(*b, so)->eval(wi, wo) == svd->eval(wi, wo)).all());
  CHECK((fit_shk(*b, ko)->eval(wi, wo) == shk->eval(wi, wo)).all());
  CHECK((fit_shr(*b, ro)->eval(wi, wo) == shr->eval(wi, wo)).all());
  CHECK((refine(*fit, s, rf)->eval(wi, wo) == refined->eval(wi, wo)).all());
  CHECK(fit_model(s, mo).cost == model.cost);
}
