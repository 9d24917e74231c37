// The whole-domain fill of raw samples (experiments/run/symmetry_prep.h,
// docs/design.md §4.5): the key, what it appends, where "auto" applies, and
// what it does to a run on real measured samples.
#include <set>

#include "brdfs/catalogue.h"
#include "brdfs/measured.h"
#include "brdfs/merl.h"
#include "brdfs/models.h"
#include "experiments/report/outputs.h"
#include "experiments/report/validation.h"
#include "experiments/run/symmetry_prep.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {

std::string fill_config(const std::string& sampling, const std::string& method, const std::string& extra = "") {
  return "[experiment]\nseed = 3\nplots = false\nrender = false\nexport = false\nvalidation_pairs = 1024\n" +
         extra + "[[brdf]]\nmodel = \"krylon-blue\"\n[sampling]\n" + sampling + "\n[[method]]\n" + method + "\n";
}

// Scattered samples of an isotropic model over the whole domain, declaring all three symmetries.
std::shared_ptr<MeasuredBrdf> declared_interpolant(bool declare) {
  SampleSet s = sample_stratified(*Catalogue::builtin().make("cook-torrance"), 600, 4);
  s.symmetries = declare ? Symmetries::all() : Symmetries::none();  // a stratified set declares the model's
  return std::make_shared<MeasuredBrdf>("planted", s, MeasuredOptions{});
}

const SymmetryChoice kOrbit{Symmetries::all(), Symmetries::all(), "auto"};

SamplingVariant measured_sampling(double fill) {
  SamplingVariant s;
  s.kind = "measured";
  s.fill = fill;
  s.where = "cfg.toml:7";
  return s;
}

}  // namespace

TEST_CASE("fill: the key applies to measured sets only and bad values name the key") {
  require_one_config_error("[experiment]\nname = \"t\"\n[[brdf]]\npreset = \"bluepaint\"\n[sampling]\nkind = "
                           "\"grid\"\nresolution = 6\nfill = 0.3\n[[method]]\nkind = \"mccool\"\n",
                           {"sampling.fill", "measured", "grid"});
  require_one_config_error(fill_config("kind = \"measured\"\nfill = 0.95", "kind = \"mccool\""),
                           {"sampling.fill", "0.9", "0.95"});
  require_one_config_error(fill_config("kind = \"measured\"\nfill = \"always\"", "kind = \"mccool\""),
                           {"sampling.fill", "always", "auto"});
}

TEST_CASE("fill: the key and its constants are part of a measured sampling's identity") {
  register_loaders();
  const auto identity = [](const std::string& sampling) {
    return parse_plan(fill_config(sampling, "kind = \"mccool\"\ntexture_size = 4"), "cfg.toml", {}).samplings.at(0);
  };
  const SamplingVariant a = identity("kind = \"measured\"");
  CHECK(a.fill < 0);
  CHECK(a.identity.at("fill") == "auto");
  CHECK(a.identity.at("fill_pairs") == kFillPairs);
  CHECK(a.identity.at("fill_share") == kFillShare);
  const SamplingVariant off = identity("kind = \"measured\"\nfill = \"off\"");
  CHECK(off.fill == 0.0);
  CHECK_FALSE(off.identity.contains("fill_pairs"));
  const SamplingVariant half = identity("kind = \"measured\"\nfill = 0.5");
  CHECK(half.fill == 0.5);
  CHECK(half.identity.at("fill") == 0.5);
  CHECK(short_hash(a.identity) != short_hash(off.identity));
  CHECK(short_hash(a.identity) != short_hash(half.identity));
}

TEST_CASE("fill: the training interpolant's pairs carry exactly the share of the weight") {
  const auto truth = declared_interpolant(true);
  const FillChoice f = choose_fill(measured_sampling(-1.0), truth.get(), kOrbit, 77);
  REQUIRE(f.truth == truth.get());
  CHECK(f.share == kFillShare);
  CHECK(f.pairs == kFillPairs);
  SampleSet fit = sample_stratified(*Catalogue::builtin().make("lambert"), 50, 9);
  fit.weight.assign(fit.size(), 2.0);  // total 100
  const SampleSet out = with_fill(fit, f);
  REQUIRE(out.size() == 50 + kFillPairs);
  REQUIRE(out.weight.size() == out.size());
  double filled = 0, total = 0;
  for (size_t k = 0; k < out.size(); ++k) {
    total += out.weight_of(k);
    if (k >= 50) filled += out.weight_of(k);
  }
  CHECK(filled / total == Approx(kFillShare).epsilon(1e-12));
  for (size_t k = 0; k < 50; ++k) CHECK(out.weight_of(k) == 2.0);  // the fit's own samples untouched
  for (size_t k = 50; k < out.size(); k += 997)
    CHECK((out.value[k] - truth->eval(out.wi[k], out.wo[k])).abs().maxCoeff() == 0.0);
  // The fill never samples the whole-domain validation pairs of the same experiment seed.
  const FillChoice g = choose_fill(measured_sampling(-1.0), truth.get(), kOrbit, fill_seed(3));
  const SampleSet pairs = with_fill(fit, g);
  REQUIRE(pairs.size() == 50 + kFillPairs);
  // The default ("auto") set: every block that a run may score.
  const SampleSet val = domain_set(*truth, ExperimentSettings::kValidationAuto, validation_seed(3)).pairs;
  REQUIRE(val.size() == size_t(ExperimentSettings::kValidationMaxBlocks) * ExperimentSettings::kValidationBlockPairs);
  std::set<std::pair<double, double>> seen;
  for (size_t k = 0; k < val.size(); ++k) seen.insert({val.wi[k].x(), val.wo[k].y()});
  size_t shared = 0;
  for (size_t k = 50; k < pairs.size(); ++k) shared += seen.count({pairs.wi[k].x(), pairs.wo[k].y()});
  CHECK(shared == 0);
  // A fill drawn like the validation set (its count and seed) is seen as a leak.
  FillChoice same = g;
  same.pairs = ExperimentSettings::kValidationBlockPairs;  // block 0's count and seed
  same.seed = validation_seed(3);
  const SampleSet leak = with_fill(fit, same);
  size_t leaked = 0;
  for (size_t k = 50; k < leak.size(); ++k) leaked += seen.count({leak.wi[k].x(), leak.wo[k].y()});
  CHECK(leaked > 0);
  CHECK(fill_seed(3) != validation_seed(3));
}

namespace {
// A BRDF with no value anywhere (every pair masked).
class NowhereBrdf final : public Brdf {
 public:
  Rgb eval(const Vec3&, const Vec3&) const override { return Rgb::Constant(-1.0); }
  std::string name() const override { return "nowhere"; }
  std::string to_string() const override { return "nowhere"; }
};
}  // namespace

TEST_CASE("fill: a fill with nothing to add refuses naming the key instead of fitting unfilled") {
  SampleSet fit = sample_stratified(*Catalogue::builtin().make("lambert"), 50, 9);
  NowhereBrdf nowhere;
  FillChoice f;
  f.truth = &nowhere;
  f.share = kFillShare;
  f.pairs = 256;
  f.seed = 5;
  CHECK_THROWS_WITH(with_fill(fit, f), Catch::Contains("sampling.fill") && Catch::Contains("none of the 256") &&
                                           Catch::Contains("nowhere"));
  const auto truth = declared_interpolant(true);
  f.truth = truth.get();
  CHECK_THROWS_WITH(with_fill(SampleSet{}, f), Catch::Contains("sampling.fill") && Catch::Contains("no valid sample"));
  CHECK(with_fill(fit, f).size() == 50 + 256);
}

TEST_CASE("fill: auto leaves undeclared samples and fits without symmetries alone and a share set there is refused") {
  const auto undeclared = declared_interpolant(false);
  const FillChoice a = choose_fill(measured_sampling(-1.0), undeclared.get(), kOrbit, 1);
  CHECK(a.truth == nullptr);
  CHECK_THAT(a.why, Catch::Contains("declare"));
  CHECK(choose_fill(measured_sampling(-1.0), nullptr, kOrbit, 1).truth == nullptr);
  CHECK(choose_fill(measured_sampling(0.0), declared_interpolant(true).get(), kOrbit, 1).truth == nullptr);
  // symmetries = "off": the fit sees the records alone, and auto adds nothing to them.
  const FillChoice records = choose_fill(measured_sampling(-1.0), declared_interpolant(true).get(),
                                         SymmetryChoice{Symmetries::all(), Symmetries{}, "off"}, 1);
  CHECK(records.truth == nullptr);
  CHECK_THAT(records.why, Catch::Contains("symmetries = \"off\""));
  CHECK_THROWS_WITH(choose_fill(measured_sampling(0.3), undeclared.get(), kOrbit, 1),
                    Catch::Contains("cfg.toml:7") && Catch::Contains("sampling.fill") && Catch::Contains("declare"));
  // A MERL table holds over the whole domain: auto fills it too (its cells sit on one
  // slice of (theta_h, theta_d, phi_d) at their centres; the fill reads its lookup between them).
  const MerlBrdf merl(std::make_shared<const MerlTable>(merl_tabulate(Lambert(LambertParams{}))),
                      MerlLookup::Linear, "lambert.binary");
  CHECK(choose_fill(measured_sampling(-1.0), &merl, kOrbit, 1).share == kFillShare);
  // A set share on a BRDF that holds is used as given.
  CHECK(choose_fill(measured_sampling(0.5), declared_interpolant(true).get(), kOrbit, 1).share == 0.5);
}

TEST_CASE("fill: on raw Cornell samples the fit follows the interpolant off the measured slice") {
  ScratchDir tmp;
  const std::string mccool = "kind = \"mccool\"\ntexture_size = 16";
  const std::string extra = "holdout = 0.1\n";
  run_quiet(write_text(tmp / "on.toml", fill_config("kind = \"measured\"", mccool, extra)), tmp / "on");
  run_quiet(write_text(tmp / "off.toml", fill_config("kind = \"measured\"\nfill = \"off\"", mccool, extra)), tmp / "off");
  const Row on = read_results_csv(tmp / "on/results.csv").at(0);
  const Row off = read_results_csv(tmp / "off/results.csv").at(0);
  INFO("val " << on.at("val_rel_mse") << " vs " << off.at("val_rel_mse") << ", held-out " << on.at("holdout_rel_mse")
              << " vs " << off.at("holdout_rel_mse"));
  CHECK(on.at("samples") == off.at("samples"));  // training metrics stay on the raw samples
  CHECK(std::stod(on.at("val_rel_mse")) < 0.7 * std::stod(off.at("val_rel_mse")));
  CHECK(std::stod(on.at("holdout_rel_mse")) < 1.25 * std::stod(off.at("holdout_rel_mse")));
  const nlohmann::json rec = nlohmann::json::parse(read_text(tmp / ("on/runs/" + on.at("run_id") + "/run.json")));
  CHECK(rec.at("fill").at("used") == true);
  CHECK(rec.at("fill").at("pairs") == kFillPairs);
  CHECK(rec.at("fill").at("share") == kFillShare);
  // The fill's truth is the interpolant of the 1,295 training samples, never of the held-out ones.
  CHECK_THAT(rec.at("fill").at("truth").get<std::string>(), Catch::Contains("1295 valid samples"));
  const nlohmann::json rec_off =
      nlohmann::json::parse(read_text(tmp / ("off/runs/" + off.at("run_id") + "/run.json")));
  CHECK(rec_off.at("fill").at("used") == false);
  CHECK_THAT(rec_off.at("fill").at("why").get<std::string>(), Catch::Contains("off"));
}
