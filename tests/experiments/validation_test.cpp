// Validation on data the fit never saw (experiments/report/validation.h): held-out
// samples, the whole-domain set, the default scene's shade_rmse, tolerances
// on shade_rmse, and the flags.
#include <algorithm>
#include <cmath>

#include "brdfs/catalogue.h"
#include "brdfs/merl.h"
#include "brdfs/models.h"
#include "brdfs/sample_csv.h"
#include "experiments/config/config.h"
#include "experiments/report/validation.h"
#include "factor/size_choice.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {

// c x the wrapped BRDF (a planted approximation whose peak ratio is c).
class Scaled : public Brdf {
 public:
  Scaled(BrdfPtr b, double c) : b_(std::move(b)), c_(c) {}
  Rgb eval(const Vec3& wi, const Vec3& wo) const override { return c_ * b_->eval(wi, wo); }
  std::string name() const override { return "scaled"; }
  std::string to_string() const override { return "scaled"; }

 private:
  BrdfPtr b_;
  double c_;
};

std::string lines_of(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& l : v) s += l + "\n";
  return s;
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> out;
  size_t a = 0;
  while (a < text.size()) {
    size_t b = text.find('\n', a);
    if (b == std::string::npos) b = text.size();
    out.push_back(text.substr(a, b - a));
    a = b + 1;
  }
  return out;
}

std::string val_row_text(const Row& r) {
  std::string s;
  for (const auto& [k, v] : r) s += k + "=" + v + " ";
  return s;
}

double val_num(const Row& r, const std::string& k) {
  INFO(k << " = '" << r.at(k) << "'");
  REQUIRE(!r.at(k).empty());
  return std::stod(r.at(k));
}

}  // namespace

TEST_CASE("validation: the held-out split is deterministic, disjoint and of the stated size") {
  const BrdfPtr b = Catalogue::builtin().make("bluepaint");
  const SampleSet s = sample_grid(*b, 6);
  const HoldoutSplit a = split_holdout(s, 0.1, 42), a2 = split_holdout(s, 0.1, 42), c = split_holdout(s, 0.1, 43);
  const size_t n = s.valid_count();
  CHECK(a.held.valid_count() == static_cast<size_t>(std::llround(0.1 * double(n))));
  CHECK(a.train.valid_count() + a.held.valid_count() == n);
  CHECK(a.held.wi == a2.held.wi);
  CHECK(a.held.wi != c.held.wi);  // another seed, another choice
  // Every held-out pair is absent from the training set.
  for (size_t k = 0; k < a.held.size(); ++k)
    for (size_t j = 0; j < a.train.size(); ++j)
      REQUIRE(!(a.held.wi[k] == a.train.wi[j] && a.held.wo[k] == a.train.wo[j]));
  CHECK(split_holdout(s, 0.0, 1).held.size() == 0);
  CHECK_THROWS_WITH(split_holdout(s, 0.7, 1), Catch::Contains("0..0.5"));
}

TEST_CASE("validation: held-out samples are never fitted - perturbing only them leaves the fit unchanged") {
  ScratchDir tmp;
  // A sample list of bluepaint; the runner reads it back as `file` samples.
  const BrdfPtr bp = Catalogue::builtin().make("bluepaint");
  const std::string clean = tmp / "clean.csv";
  write_sample_csv(sample_grid(*bp, 6), clean);
  const SampleSet loaded = read_sample_csv(clean);
  const uint64_t seed = 5;
  const HoldoutSplit split = split_holdout(loaded, 0.1, validation_seed(seed));
  REQUIRE(split.held.valid_count() > 10);
  // The perturbed file: the same text, held-out rows' values x 7.
  std::vector<std::string> lines = split_lines(read_text(clean));
  size_t row = 0, changed = 0;
  for (auto& l : lines) {
    if (l.empty() || l[0] == '#' || l.rfind("theta_i", 0) == 0) continue;
    const size_t k = row++;
    bool held = false;
    for (size_t h = 0; h < split.held.size(); ++h)
      held = held || (split.held.wi[h] == loaded.wi[k] && split.held.wo[h] == loaded.wo[k]);
    if (!held) continue;
    std::vector<std::string> cells;
    size_t a = 0;
    for (size_t b; (b = l.find(',', a)) != std::string::npos; a = b + 1) cells.push_back(l.substr(a, b - a));
    cells.push_back(l.substr(a));
    for (int c = 4; c < 7; ++c) cells[c] = std::to_string(7.0 * std::stod(cells[c]));
    l.clear();
    for (size_t i = 0; i < cells.size(); ++i) l += (i ? "," : "") + cells[i];
    ++changed;
  }
  REQUIRE(row == loaded.size());
  REQUIRE(changed == split.held.size());
  const std::string perturbed = write_text(tmp / "perturbed.csv", lines_of(lines));

  auto config = [&](const std::string& csv) {
    return "[experiment]\nseed = 5\nholdout = 0.1\nplots = false\nrender = false\nexport = false\n"
           "[[brdf]]\npreset = \"bluepaint\"\n[sampling]\nkind = \"file\"\npath = \"" + csv +
           "\"\n[[method]]\nkind = \"mccool\"\ntexture_size = 6\n";
  };
  run_quiet(write_text(tmp / "a.toml", config(clean)), tmp / "a");
  run_quiet(write_text(tmp / "b.toml", config(perturbed)), tmp / "b");
  const Row ra = read_results_csv(tmp / "a/results.csv").at(0), rb = read_results_csv(tmp / "b/results.csv").at(0);
  INFO(val_row_text(ra) << "\n" << val_row_text(rb));
  // The fit saw the same training samples: identical training metrics and
  // identical whole-domain scores (the domain set is scored against the BRDF).
  CHECK(ra.at("samples") == std::to_string(split.train.valid_count()));
  CHECK(ra.at("samples") == rb.at("samples"));
  for (const char* k : {"rel_mse", "cos_rmse", "lin_rmse", "val_rel_mse", "val_cos_rmse", "val_max_ratio"})
    CHECK(ra.at(k) == rb.at(k));
  // ...while the held-out metric moves: log(7)^2 ~ 3.8 more in log space.
  CHECK(val_num(rb, "holdout_rel_mse") > val_num(ra, "holdout_rel_mse") + 1.0);
  CHECK(ra.at("validation").find("held out: " + std::to_string(split.held.valid_count()) + " of " +
                                 std::to_string(loaded.valid_count())) != std::string::npos);
}

TEST_CASE("validation: a config without [scene] gets shade_rmse from the default scene, and can drop it") {
  ScratchDir tmp;
  const std::string body = R"(
[experiment]
plots = false
render = false
export = false
[[brdf]]
preset = "bluepaint"
[sampling]
kind = "grid"
resolution = 6
[[method]]
kind = "mccool"
texture_size = 6
)";
  run_quiet(write_text(tmp / "a.toml", body), tmp / "a");
  const Row r = read_results_csv(tmp / "a/results.csv").at(0);
  INFO(val_row_text(r));
  CHECK(val_num(r, "shade_rmse") > 0.0);
  CHECK(val_num(r, "val_rel_mse") >= 0.0);
  CHECK(r.at("validation").find("stratified pairs in") != std::string::npos);  // the default, "auto"
  CHECK(r.at("validation").find("blocks of 4096") != std::string::npos);
  CHECK(r.at("holdout_rel_mse").empty());  // grid samples: nothing is held out
  run_quiet(write_text(tmp / "b.toml", body + "[scene]\nshade_rmse = false\n"), tmp / "b");
  CHECK(read_results_csv(tmp / "b/results.csv").at(0).at("shade_rmse").empty());
  run_quiet(write_text(tmp / "c.toml", body), tmp / "c", {"experiment.validation_pairs=0"});
  CHECK(read_results_csv(tmp / "c/results.csv").at(0).at("val_rel_mse").empty());
}

TEST_CASE("validation: a shade_rmse tolerance picks the smallest size meeting it, for baselines and homomorphic fits") {
  ScratchDir tmp;
  const std::string head = R"(
[experiment]
plots = false
render = false
export = false
[[brdf]]
preset = "cole-cook-torrance"
[sampling]
kind = "grid"
resolution = 6
[scene]
size = 32
)";
  struct Case {
    std::string kind_body;  // the method with an explicit size `%`
    std::string knob;       // results column of the size
    std::vector<int> sizes;
    std::string tolerance_body;
  };
  const std::string fit3 = "kind = \"fit\"\nprojections = [{ name = \"wi\" }, { name = \"h\" }, { name = \"wo\" }]\n"
                           "texture_size = 6\n";
  const std::vector<Case> cases = {
      {"kind = \"sh-k\"\norder = %\n", "order", {1, 2, 3, 4, 5}, "kind = \"sh-k\"\norder = 5\n"},
      {"kind = \"mccool\"\ntexture_size = %\n", "texture_size", {4, 6, 8},
       "kind = \"mccool\"\ntexture_size = \"auto\"\ntexture_ladder = [4, 6, 8]\n"},
      {fit3 + "terms = %\n", "terms", {1, 2, 3}, fit3 + "terms = 3\n"},
  };
  int ci = 0;
  for (const auto& cs : cases) {
    ++ci;
    std::string explicit_cfg = head;
    for (int v : cs.sizes) {
      std::string b = cs.kind_body;
      b.replace(b.find('%'), 1, std::to_string(v));
      explicit_cfg += "[[method]]\n" + b;
    }
    const std::string dir = tmp / ("e" + std::to_string(ci));
    run_quiet(write_text(dir + ".toml", explicit_cfg), dir);
    const auto rows = read_results_csv(dir + "/results.csv");
    REQUIRE(rows.size() == cs.sizes.size());
    std::vector<double> shade;
    for (const auto& r : rows) shade.push_back(val_num(r, "shade_rmse"));
    std::ostringstream by_size;
    for (double v : shade) by_size << v << " ";
    INFO(cs.kind_body << " shade_rmse by size: " << by_size.str());
    // A target between the best and the worst: the expected choice is the
    // smallest size whose explicit run meets it.
    const double best = *std::min_element(shade.begin(), shade.end());
    REQUIRE(best < shade[0]);
    const double target = std::sqrt(best * shade[0]);
    size_t expect = 0;
    while (shade[expect] > target) ++expect;
    std::ostringstream tol;
    tol.precision(17);
    tol << "tolerance = { metric = \"shade_rmse\", value = " << target << " }\n";
    const std::string tdir = tmp / ("t" + std::to_string(ci));
    run_quiet(write_text(tdir + ".toml", head + "[[method]]\n" + cs.tolerance_body + tol.str()), tdir);
    const Row t = read_results_csv(tdir + "/results.csv").at(0);
    INFO(val_row_text(t));
    CHECK(t.at(cs.knob) == std::to_string(cs.sizes[expect]));
    CHECK(t.at("tolerance_reached") == "true");
    CHECK(std::abs(val_num(t, "shade_rmse") - shade[expect]) <= 1e-9 * shade[expect]);
  }
}

TEST_CASE("validation: peak_ratio has its closed form and flags mark planted bad runs") {
  const BrdfPtr b = Catalogue::builtin().make("bluepaint");
  const DomainSet dom{validation_set(*b, 512, 9)};
  CHECK(peak_ratio(*b, dom.pairs) == Approx(1.0));
  CHECK(peak_ratio(Scaled(b, 50.0), dom.pairs) == Approx(50.0));
  CHECK(peak_ratio(Scaled(b, std::nan("")), dom.pairs) == 1e300);

  const LogTransform lt = LogTransform::of(dom.pairs);
  // A good approximation: no flag.
  {
    Row row;
    std::vector<std::string> notes;
    fill_validation_columns(score_validation(*b, &dom, nullptr, lt), 0.01, "s", row, notes);
    CHECK(row.at("flag").empty());
    CHECK(notes.empty());
  }
  // 50x the BRDF: both the error and the peak ratio are flagged, with reasons.
  {
    Row row;
    std::vector<std::string> notes;
    fill_validation_columns(score_validation(Scaled(b, 50.0), &dom, nullptr, lt), 0.01, "s", row, notes);
    CHECK(row.at("flag") == "val_rel_mse,val_max_ratio");
    REQUIRE(notes.size() == 2);
    CHECK(notes[0].find("flag: val_rel_mse") == 0);
    CHECK(notes[1].find("flag: val_max_ratio 50 > 10") == 0);
  }
  // A validation error far above training but under the floor: not flagged.
  {
    Row row;
    std::vector<std::string> notes;
    fill_validation_columns(score_validation(Scaled(b, 1.1), &dom, nullptr, lt), 1e-9, "s", row, notes);
    CHECK(val_num(row, "val_rel_mse") < kFlagErrorFloor);
    CHECK(row.at("flag").empty());
  }
}

TEST_CASE("validation: tolerances on external metrics need their source") {
  Tolerance t;
  t.metric = "shade_rmse";
  t.value = 0.1;
  CHECK_THROWS_WITH(t.validate(), Catch::Contains("needs a scorer"));
  t.score = [](const Brdf&) { return 0.0; };
  CHECK_NOTHROW(t.validate());
  const std::string body = std::string(kConfigHead) +
                           "[[method]]\nkind = \"svd\"\ntolerance = { metric = \"shade_rmse\", value = 0.1 }\n";
  register_loaders();
  CHECK_THROWS_WITH(parse_plan(body + "[scene]\nshade_rmse = false\n", "cfg.toml"),
                    Catch::Contains("[scene] shade_rmse = false"));
  const std::string val = std::string(kConfigHead) +
                          "[[method]]\nkind = \"svd\"\ntolerance = { metric = \"val_rel_mse\", value = 0.1 }\n";
  CHECK_THROWS_WITH(parse_plan(val, "cfg.toml", {"experiment.validation_pairs=0"}),
                    Catch::Contains("validation_pairs = 0"));
  CHECK_NOTHROW(parse_plan(val, "cfg.toml"));
}

TEST_CASE("validation: pairs where a measured truth has no data are skipped and counted") {
  // A MERL table of a Lambertian with every theta_d >= 60 deg cell missing.
  auto t = std::make_shared<MerlTable>(merl_tabulate(Lambert(LambertParams{})));
  for (int h = 0; h < kMerlThetaH; ++h)
    for (int d = 60; d < kMerlThetaD; ++d)
      for (int p = 0; p < kMerlPhiD; ++p) t->raw[merl_cell(h, d, p)] = -1.0;
  const MerlBrdf truth(t, MerlLookup::Nearest, "holes");
  const SampleSet dom = validation_set(truth, 1024, 3);
  const size_t skipped = dom.size() - dom.valid_count();
  CHECK(skipped > 50);  // pairs with theta_d >= 60 deg: a sizeable share of the hemisphere pair
  CHECK(skipped < dom.size() / 2);
  CHECK_THAT(dom.description, Catch::Contains(std::to_string(skipped) + " where the truth has no data skipped"));
  // The Lambertian it was tabulated from matches the truth wherever the truth has data.
  const Lambert lambert{LambertParams{}};
  const DomainSet whole{dom};
  const ValidationScores v = score_validation(lambert, &whole, nullptr, LogTransform::of(dom));
  CHECK(v.val.rel_mse < 1e-20);
  CHECK(v.val.samples == dom.valid_count());
  // A truth with data everywhere skips nothing.
  const SampleSet full = validation_set(lambert, 1024, 3);
  CHECK(full.valid_count() == full.size());
  CHECK_THAT(full.description, !Catch::Contains("skipped"));
}
