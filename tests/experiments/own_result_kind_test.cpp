// A method kind with a result type of its own, defined in this file and
// registered by one line: a run of it through a config writes its export and
// its viewer data, its GLSL compiles for every target, the export reloads
// once its (optional) reader is registered, report.html's viewer
// lists it, and Python's binding table (method_call_specs, which
// python/src/methods.cpp binds as bf.<kind> and bf.factor(kind)) has it with
// its keys documented. Nothing outside this file names it. (The Python module
// is built from the library, without the test tree, so the Python side is
// checked on the table the module is bound from.)
#include <fstream>

#include "brdfs/catalogue.h"
#include "experiments/methods/method_kind.h"
#include "experiments_helpers.h"
#include "factor/export.h"
#include "factor/glsl_compile.h"
#include "factor/glsl_target.h"
#include "factor/metrics.h"

using namespace bf;
using namespace bf_test;

namespace {

// A tinted Lambertian: one RGB value above the horizon. Its outputs: STEM.json
// (its description) and STEM.glsl, the same formula as the viewer's.
class TintFactorization final : public Factorization {
 public:
  explicit TintFactorization(Rgb rho) : rho_(rho) {}
  Rgb eval(const Vec3& wi, const Vec3& wo) const override {
    return wi.z() > 0 && wo.z() > 0 ? rho_ : Rgb::Zero();
  }
  std::string name() const override { return "tint"; }
  std::string to_string() const override { return "tint"; }
  std::string method() const override { return "toy-tint"; }
  size_t storage_floats() const override { return 3; }
  nlohmann::json describe() const override { return {{"method", "toy-tint"}, {"rho", {rho_[0], rho_[1], rho_[2]}}}; }

  ExportedFiles write_export_files(const std::string& dir, const std::string& stem,
                                   const std::string& origin) const override {
    if (stem.empty() || stem.find('/') != std::string::npos)
      throw std::invalid_argument("export: stem: expected a non-empty name without '/', found \"" + stem + "\"");
    fs::create_directories(dir);
    ExportedFiles e;
    e.sidecar = (fs::path(dir) / (stem + ".json")).string();
    e.glsl = (fs::path(dir) / (stem + ".glsl")).string();
    std::ofstream(e.glsl) << glsl(stem, origin);
    std::ofstream(e.sidecar) << describe().dump(1) << "\n";
    return e;
  }
  std::string glsl(const std::string& stem, const std::string& origin) const override {
    (void)stem;
    return "// toy-tint " + origin + "\n" + glsl_target_prelude() +
           "vec3 brdf_factor_eval(vec3 wi, vec3 wo) {\n  return (wi.z > 0.0 && wo.z > 0.0) ? vec3(" +
           glsl_float(rho_[0], "rho") + ", " + glsl_float(rho_[1], "rho") + ", " + glsl_float(rho_[2], "rho") +
           ") : vec3(0.0);\n}\n";
  }
  std::optional<ShaderView> viewer_data() const override { return ShaderView{glsl("factors", "viewer"), {}}; }

 private:
  Rgb rho_;
};

// kind = "toy-tint": the samples' mean times `gain`; its options stay in
// MethodVariant::extra (no field of its own there).
class ToyTintKind final : public MethodKind {
 public:
  std::string name() const override { return "toy-tint"; }
  std::string summary() const override { return "The samples' mean as a tinted Lambertian (a test kind)."; }
  std::vector<KeySpec> keys() const override {
    return {num_key("gain", 0.0, 10.0, true, "1", "multiplies the samples' mean")};
  }
  std::string example() const override { return "gain = 1\n"; }
  std::vector<std::string> described() const override { return {"gain"}; }
  std::vector<std::string> columns() const override { return {}; }
  void read(Reader& r, MethodVariant& m, nlohmann::json& o, uint64_t) const override {
    const double gain = r.number(keys()[0], 1.0);
    o["gain"] = gain;
    kind_options<double>(m) = gain;
  }
  MethodOutcome run(const RunContext& c) const override {
    Rgb sum = Rgb::Zero();
    double n = 0;
    for (size_t i = 0; i < c.samples.size(); ++i)
      if (c.samples.valid[i]) sum += c.samples.value[i], n += 1;
    MethodOutcome out;
    out.result = std::make_shared<TintFactorization>(sum / n * kind_options<double>(c.method));
    return out;
  }
  void fill_row(const RunContext&, MethodOutcome&, Row&) const override {}
  void export_files(const RunContext& c, const MethodOutcome& out) const override {
    write_description(c, out);
    write_export(*out.result, c.run_dir.string(), "factors", "run " + c.run.run_id);
  }
};

// Reads a toy-tint export back (its optional reader: load_export, --brdf).
std::shared_ptr<const Factorization> read_tint(const std::string& path) {
  const nlohmann::json j = nlohmann::json::parse(read_text(path));
  const auto& rho = j.at("rho");
  return std::make_shared<TintFactorization>(Rgb(rho[0].get<double>(), rho[1].get<double>(), rho[2].get<double>()));
}

// The JSON object a viewer.js assigns.
nlohmann::json viewer_json(const std::string& text) {
  const size_t a = text.find("] = "), b = text.rfind(';');
  REQUIRE(a != std::string::npos);
  REQUIRE(b != std::string::npos);
  return nlohmann::json::parse(text.substr(a + 4, b - a - 4));
}

const char* kConfig = R"([experiment]
name = "t"
plots = false

[scene]
size = 16

[[brdf]]
preset = "bluepaint"

[sampling]
kind = "grid"
resolution = 6

[[method]]
kind = "toy-tint"
gain = 2
)";

}  // namespace

TEST_CASE("kinds: a kind with its own result type gets export GLSL viewer and Python from its file and one line") {
  const ScopedMethodKind registered(std::make_shared<ToyTintKind>());  // the one registration line

  ScratchDir tmp;
  const RunSummary s = run_quiet(write_text(tmp / "cfg.toml", kConfig), tmp / "out");
  REQUIRE(s.failed == 0);
  const auto rows = read_results_csv(tmp / "out/results.csv");
  REQUIRE(rows.size() == 1);
  CHECK(rows[0].at("method") == "toy-tint");
  const fs::path run = fs::path(tmp / "out/runs") / rows[0].at("run_id");

  // The export: the result's own files, its GLSL compiling for every target.
  REQUIRE(fs::exists(run / "factors.json"));
  REQUIRE(fs::exists(run / "factors.glsl"));
  CHECK(nlohmann::json::parse(read_text((run / "factors.json").string())).at("method") == "toy-tint");
  const std::string glsl = read_text((run / "factors.glsl").string());
  CHECK(glsl.find("run " + rows[0].at("run_id")) != std::string::npos);
  const std::string err = compile_glsl_all_targets(glsl, tmp.path);
  INFO(err);
  CHECK(err.empty());
  {  // With its reader registered, the export reloads as a BRDF spec and scores the run's rel_mse.
    register_export_reader("toy-tint", read_tint);
    struct Unregister {
      ~Unregister() { register_export_reader("toy-tint", nullptr); }
    } unregister;
    register_loaders();
    const BrdfPtr back = Catalogue::global().make((run / "factors.json").string());
    const SampleSet samples = sample_grid(*Catalogue::builtin().make("bluepaint"), 6);
    const double got = evaluate_metrics(*back, samples, LogTransform::of(samples, 1e-5)).rel_mse;
    const double want = std::stod(rows[0].at("rel_mse"));
    CHECK(std::abs(got - want) <= 1e-6 * std::abs(want));
  }

  // The viewer: viewer.js holds the result's viewer data, and report.html lists the run.
  REQUIRE(fs::exists(run / "viewer.js"));
  const nlohmann::json v = viewer_json(read_text((run / "viewer.js").string()));
  CHECK(v.at("method") == "toy-tint");
  CHECK(v.at("textures").empty());
  const std::string view_glsl = v.at("glsl").get<std::string>();
  CHECK(view_glsl.substr(view_glsl.find("\n")) == glsl.substr(glsl.find("\n")));  // same formula, other origin
  CHECK(compile_glsl_all_targets(view_glsl, tmp.path).empty());
  CHECK(read_text((tmp / "out/report.html")).find("runs/" + rows[0].at("run_id") + "/viewer.js") !=
        std::string::npos);

  // Python: the table the module binds bf.<kind> and bf.factor(kind) from.
  bool found = false;
  for (const MethodCallSpec& spec : method_call_specs())
    if (spec.kind == "toy-tint") {
      found = true;
      CHECK(spec.function == "toy_tint");
      CHECK(spec.input == "samples");
      CHECK(spec.doc.rfind("toy_tint(samples, **options) -> Factorization", 0) == 0);
      CHECK(spec.doc.find("gain: number in (0, 10] (1). multiplies the samples' mean") != std::string::npos);
    }
  CHECK(found);
}

TEST_CASE("kinds: a kind that declares a viewer but whose result has none fails its run naming both") {
  // The result type has no viewer_data (the default): with render and export
  // on, the run fails instead of silently writing no viewer.js.
  struct Plain final : Factorization {
    Rgb eval(const Vec3&, const Vec3&) const override { return Rgb::Constant(0.1); }
    std::string name() const override { return "plain"; }
    std::string to_string() const override { return "plain"; }
    std::string method() const override { return "toy-plain"; }
    size_t storage_floats() const override { return 3; }
    nlohmann::json describe() const override { return {{"method", "toy-plain"}}; }
  };
  struct PlainKind final : MethodKind {
    std::string name() const override { return "toy-plain"; }
    std::string summary() const override { return "A constant (a test kind)."; }
    std::vector<KeySpec> keys() const override { return {}; }
    std::string example() const override { return ""; }
    std::vector<std::string> described() const override { return {}; }
    std::vector<std::string> columns() const override { return {}; }
    void read(Reader&, MethodVariant&, nlohmann::json&, uint64_t) const override {}
    MethodOutcome run(const RunContext&) const override {
      MethodOutcome out;
      out.result = std::make_shared<Plain>();
      return out;
    }
    void fill_row(const RunContext&, MethodOutcome&, Row&) const override {}
  };
  const ScopedMethodKind registered(std::make_shared<PlainKind>());
  ScratchDir tmp;
  std::string cfg = kConfig;
  cfg.replace(cfg.find("kind = \"toy-tint\"\ngain = 2\n"), std::string("kind = \"toy-tint\"\ngain = 2\n").size(),
              "kind = \"toy-plain\"\n");
  // run_experiment throws when a run failed, after writing every table.
  std::string err;
  try {
    run_quiet(write_text(tmp / "cfg.toml", cfg), tmp / "out");
  } catch (const std::exception& e) {
    err = e.what();
  }
  INFO(err);
  CHECK(err.find("1 of 1 runs failed") != std::string::npos);
  CHECK(err.find("Factorization::viewer_data") != std::string::npos);
  const auto rows = read_results_csv(tmp / "out/results.csv");
  REQUIRE(rows.size() == 1);
  CHECK(rows[0].at("status") != "ok");
  CHECK(rows[0].at("notes").find("toy-plain") != std::string::npos);
  CHECK(rows[0].at("notes").find("viewer data") != std::string::npos);
  CHECK(!fs::exists(fs::path(tmp / "out/runs") / rows[0].at("run_id") / "viewer.js"));
}
