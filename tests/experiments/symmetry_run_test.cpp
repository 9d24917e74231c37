// Symmetries in runs (experiments/run/symmetry_prep.h, docs/design.md §4.3):
// whole-domain validation only against a truth that holds, the `symmetries`
// column, and the `symmetries` sampling key.
#include "brdfs/catalogue.h"
#include "brdfs/merl.h"
#include "brdfs/sample_csv.h"
#include "experiments/report/outputs.h"
#include "experiments/run/symmetry_prep.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {

std::string symmetry_config(const std::string& brdf_line, const std::string& sampling, const std::string& method) {
  return "[experiment]\nseed = 3\nplots = false\nrender = false\nexport = false\nvalidation_pairs = 512\n"
         "[[brdf]]\n" + brdf_line + "\n[sampling]\n" + sampling + "\n[[method]]\n" + method + "\n";
}

}  // namespace

TEST_CASE("symmetry run: a planted anisotropic non-reciprocal CSV is never flagged") {
  ScratchDir tmp;
  // separable (defaults): a(wi) b(wo) c(h), neither isotropic nor reciprocal nor bilateral.
  const BrdfPtr planted = Catalogue::builtin().make("separable");
  REQUIRE_FALSE(planted->isotropic());
  REQUIRE_FALSE(planted->reciprocal());
  const std::string csv = tmp / "aniso.csv";
  write_sample_csv(sample_stratified(*planted, 3000, 2), csv);
  const std::string fit =
      "kind = \"fit\"\ntexture_size = 8\nprojections = [{ name = \"wi\" }, { name = \"wo\" }, "
      "{ name = \"h\", parameterization = \"halfdiff\" }]";

  // Truth = the CSV's interpolant, which assumes symmetries the data do not declare:
  // no whole-domain columns, the reason in `validation`, no flag.
  run_quiet(write_text(tmp / "a.toml", symmetry_config("file = \"" + csv + "\"", "kind = \"measured\"", fit)), tmp / "a");
  const Row a = read_results_csv(tmp / "a/results.csv").at(0);
  INFO("a: validation = " << a.at("validation") << ", flag = " << a.at("flag"));
  CHECK(a.at("val_rel_mse").empty());
  CHECK(a.at("val_max_ratio").empty());
  CHECK(a.at("flag").empty());
  CHECK(a.at("validation").find("no whole-domain columns") != std::string::npos);
  CHECK(a.at("validation").find("declare none") != std::string::npos);
  CHECK(!a.at("holdout_rel_mse").empty());
  CHECK(a.at("symmetries") == "none");

  // Truth = the analytic model, samples from the CSV: whole-domain columns against it, not flagged.
  run_quiet(write_text(tmp / "b.toml", symmetry_config("model = \"separable\"", "kind = \"file\"\npath = \"" + csv + "\"", fit)),
            tmp / "b");
  const Row b = read_results_csv(tmp / "b/results.csv").at(0);
  INFO("b: validation = " << b.at("validation") << ", val_rel_mse = " << b.at("val_rel_mse") << ", holdout_rel_mse = " << b.at("holdout_rel_mse") << ", rel_mse = " << b.at("rel_mse"));
  CHECK(!b.at("val_rel_mse").empty());
  // The fit generalizes over the whole domain: its error there is at the held-out level.
  CHECK(std::stod(b.at("val_rel_mse")) <= 2.0 * std::stod(b.at("holdout_rel_mse")));
  CHECK(b.at("flag").empty());
  CHECK(b.at("symmetries") == "none");
}

TEST_CASE("symmetry run: measured samples use their declared symmetries unless the key says off") {
  ScratchDir tmp;
  const std::string mccool = "kind = \"mccool\"\ntexture_size = 6";
  run_quiet(write_text(tmp / "a.toml", symmetry_config("model = \"krylon-blue\"", "kind = \"measured\"", mccool)), tmp / "a");
  const Row a = read_results_csv(tmp / "a/results.csv").at(0);
  CHECK(a.at("symmetries") == "isotropic+reciprocal+bilateral");
  CHECK(!a.at("val_rel_mse").empty());
  const std::string rec = read_text(tmp / ("a/runs/" + a.at("run_id") + "/run.json"));
  CHECK(rec.find("orbit of 8 per sample (2 rotations x swap x mirror)") != std::string::npos);
  run_quiet(write_text(tmp / "b.toml",
                       symmetry_config("model = \"krylon-blue\"", "kind = \"measured\"\nsymmetries = \"off\"", mccool)),
            tmp / "b");
  const Row b = read_results_csv(tmp / "b/results.csv").at(0);
  CHECK(b.at("symmetries") == "none");
  CHECK(a.at("run_id") != b.at("run_id"));
  CHECK(a.at("samples") == b.at("samples"));  // training metrics stay on the raw samples
  // Grid samples are left alone by default (analytic workloads do not change).
  run_quiet(write_text(tmp / "c.toml", symmetry_config("model = \"krylon-blue\"", "kind = \"grid\"\nresolution = 6", mccool)),
            tmp / "c");
  CHECK(read_results_csv(tmp / "c/results.csv").at(0).at("symmetries") == "none");
}

TEST_CASE("symmetry run: a MERL table's cells are scored over their orbit, so held-out error predicts the whole domain's") {
  ScratchDir tmp;
  // Blinn-Phong is a function of h: the fit of the cells' orbit fits the table's
  // phi_h = 0 slice, where every cell is stored, better than other azimuths. Scored
  // there alone, held-out and training errors read 3x below the whole-domain error
  // (0.0015 against 0.0046 at texture 16; at texture 8 the fit is too coarse for it to show).
  const std::string table = tmp / "blinn-phong.binary";
  write_merl(merl_tabulate(*Catalogue::builtin().make("blinn-phong")), table);
  const std::string cfg = "[experiment]\nseed = 3\nplots = false\nrender = false\nexport = false\n"
                          "validation_pairs = 4096\n[[brdf]]\nfile = \"" + table +
                          "\"\n[sampling]\nkind = \"measured\"\n[[method]]\nkind = \"mccool\"\ntexture_size = 16\n";
  run_quiet(write_text(tmp / "a.toml", cfg), tmp / "a");
  const Row a = read_results_csv(tmp / "a/results.csv").at(0);
  INFO("validation = " << a.at("validation") << "; rel_mse " << a.at("rel_mse") << ", held-out "
                       << a.at("holdout_rel_mse") << ", val " << a.at("val_rel_mse"));
  CHECK(a.at("symmetries") == "isotropic+reciprocal");
  CHECK(a.at("validation").find("scored over their orbit (isotropic+reciprocal)") != std::string::npos);
  const double train = std::stod(a.at("rel_mse")), held = std::stod(a.at("holdout_rel_mse")),
               val = std::stod(a.at("val_rel_mse"));
  CHECK(val <= 1.25 * held);
  CHECK(held <= 1.25 * val);
  CHECK(train == Approx(held).epsilon(0.05));  // 1.1 M training cells do not overfit 3 textures of 16x16
  const nlohmann::json rec = nlohmann::json::parse(read_text(tmp / ("a/runs/" + a.at("run_id") + "/run.json")));
  CHECK(rec.at("symmetries").at("metrics").get<std::string>().find("scored over their orbit") != std::string::npos);
  // Nothing held out: the training columns are still scored over the orbit, and the row says so.
  run_quiet(write_text(tmp / "b.toml", std::string(cfg).insert(cfg.find("[[brdf]]"), "holdout = 0\n")), tmp / "b");
  const Row b = read_results_csv(tmp / "b/results.csv").at(0);
  INFO("b: validation = " << b.at("validation"));
  CHECK(b.at("holdout_rel_mse").empty());
  CHECK(b.at("validation").find("scored over their orbit (isotropic+reciprocal)") != std::string::npos);
  CHECK(std::stod(b.at("rel_mse")) == Approx(train).epsilon(0.05));
}

TEST_CASE("symmetry run: only representatives are scored over their orbit, and each keeps its weight") {
  const BrdfPtr ct = Catalogue::builtin().make("cook-torrance");
  SampleSet s = sample_stratified(*ct, 30, 5);
  s.symmetries = {true, true, false};
  SamplingVariant measured;
  measured.kind = "measured";
  measured.symmetries = "auto";
  std::optional<SampleSet> storage;
  // Measured positions (Cornell, pbrt, CSV): scored where they are.
  const SymmetryChoice scattered = choose_symmetries(measured, s);
  CHECK_FALSE(scattered.score_orbit);
  CHECK(&scored_set(s, scattered, storage) == &s);
  // Cells stored at the format's convention: scored over their orbit, each at its weight.
  s.representatives = true;
  const SymmetryChoice cells = choose_symmetries(measured, s);
  REQUIRE(cells.score_orbit);
  const SampleSet& o = scored_set(s, cells, storage);
  REQUIRE(o.size() == 30 * 4);  // 2 staggered rotations x swap
  double total = 0;
  for (size_t k = 0; k < o.size(); ++k) total += o.weight_of(k);
  CHECK(total == Approx(30.0).epsilon(1e-12));
  for (size_t k = 0; k < o.size(); ++k) CHECK((o.value[k] - s.value[k / 4]).abs().maxCoeff() == 0.0);
  // Nothing is scored over an orbit the fit does not use.
  measured.symmetries = "off";
  CHECK_FALSE(choose_symmetries(measured, s).score_orbit);
}

TEST_CASE("symmetry run: a bad symmetries value names the key and the accepted values") {
  require_one_config_error("[experiment]\nname = \"t\"\n[[brdf]]\npreset = \"bluepaint\"\n[sampling]\nkind = "
                           "\"grid\"\nresolution = 6\nsymmetries = \"isotropic+round\"\n[[method]]\nkind = \"mccool\"\n",
                           {"sampling.symmetries", "isotropic+round", "bilateral"});
}

TEST_CASE("symmetry run: the fit set keeps each raw sample at its share and every sample's total weight") {
  const BrdfPtr ct = Catalogue::builtin().make("cook-torrance");
  SampleSet s = sample_stratified(*ct, 40, 3);
  s.value[5] = Rgb::Constant(-1.0);  // masked: dropped from the fit set
  s.validate();
  const SymmetryChoice c{Symmetries::all(), Symmetries::all(), "auto"};
  OrbitInfo info;
  const SampleSet f = fit_set(s, c, &info);
  REQUIRE(info.orbit_size == 8);
  REQUIRE(f.size() == 39 + 39 * 8);
  CHECK(info.samples_out == f.size());
  double total = 0;
  for (size_t k = 0; k < f.size(); ++k) total += f.weight_of(k);
  CHECK(total == Approx(39.0).epsilon(1e-12));
  // The raw samples come first, each at half its weight; its 8 orbit copies share the rest.
  size_t j = 0;
  for (size_t k = 0; k < s.size(); ++k) {
    if (!s.valid[k]) continue;
    CHECK(f.wi[j] == s.wi[k]);
    CHECK(f.wo[j] == s.wo[k]);
    CHECK(f.weight_of(j) == Approx(0.5));
    ++j;
  }
  CHECK(f.weight_of(39) == Approx(0.5 / 8));
}

TEST_CASE("symmetry run: the orbit's settings are part of a raw sampling's identity") {
  register_loaders();
  const auto sampling_identity = [](const std::string& sampling) {
    const Plan p = parse_plan(symmetry_config("model = \"krylon-blue\"", sampling, "kind = \"mccool\"\ntexture_size = 4"),
                              "cfg.toml", {});
    return p.samplings.at(0).identity;
  };
  // A run cached under other orbit constants must not be reused: they are hashed.
  const nlohmann::json on = sampling_identity("kind = \"measured\"");
  REQUIRE(on.contains("orbit"));
  CHECK(on.at("orbit") == orbit_identity());
  CHECK(on.at("orbit").at("raw_share") == kRawShare);
  CHECK_FALSE(sampling_identity("kind = \"measured\"\nsymmetries = \"off\"").contains("orbit"));
  CHECK_FALSE(sampling_identity("kind = \"grid\"\nresolution = 4").contains("orbit"));
}

TEST_CASE("sample weights: the weights key applies to measured sets only and is part of their identity") {
  register_loaders();
  require_one_config_error("[experiment]\nname = \"t\"\n[[brdf]]\npreset = \"bluepaint\"\n[sampling]\nkind = "
                           "\"grid\"\nresolution = 6\nweights = \"measure\"\n[[method]]\nkind = \"mccool\"\n",
                           {"sampling.weights", "measured", "grid"});
  require_one_config_error("[experiment]\nname = \"t\"\n[[brdf]]\nmodel = \"krylon-blue\"\n[sampling]\nkind = "
                           "\"measured\"\nweights = \"solid\"\n[[method]]\nkind = \"mccool\"\n",
                           {"sampling.weights", "solid", "measure"});
  const auto identity = [](const std::string& sampling) {
    return parse_plan(symmetry_config("model = \"krylon-blue\"", sampling, "kind = \"mccool\"\ntexture_size = 4"), "cfg.toml",
                      {})
        .samplings.at(0)
        .identity;
  };
  CHECK(identity("kind = \"measured\"").at("weights") == "auto");
  CHECK(identity("kind = \"measured\"\nweights = \"none\"").at("weights") == "none");
  CHECK_FALSE(identity("kind = \"grid\"\nresolution = 4").contains("weights"));
}

TEST_CASE("sample weights: measure weights on scattered samples are refused naming the key") {
  ScratchDir tmp;
  std::string out;
  const std::string cfg = write_text(
      tmp / "w.toml", symmetry_config("model = \"krylon-blue\"", "kind = \"measured\"\nweights = \"measure\"",
                             "kind = \"mccool\"\ntexture_size = 4"));
  CHECK(run_cli("run " + cfg + " --out " + (tmp / "o") + " --no-plots", &out) != 0);
  CHECK_THAT(out, Catch::Contains("sampling.weights") && Catch::Contains("MERL"));
}
