// The method catalogue (experiments/methods/): every registered kind runs
// from its example and fills the columns it declares; the docs' key tables
// are the catalogue's; a kind added at run time needs nothing but its class
// and one registration line.
#include "experiments/methods/method_kind.h"
#include "factor/sh_baseline.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {

std::string config_of(const std::string& kind, const std::string& body) {
  return std::string(R"([experiment]
name = "t"
render = false

[[brdf]]
preset = "bluepaint"

[sampling]
kind = "grid"
resolution = 6

[[method]]
kind = ")") + kind + "\"\n" + body;
}

}  // namespace

TEST_CASE("catalogue: every registered kind runs from its example and fills its declared columns") {
  REQUIRE(method_kinds().size() >= 7);
  for (const auto& kind : method_kinds()) {
    INFO(kind->name());
    // Declared columns exist in results.csv, and the kind's keys are unique.
    for (const auto& col : kind->columns()) CHECK(contains(result_columns(), col));
    std::set<std::string> names;
    for (const auto& k : method_keys(*kind)) CHECK(names.insert(k).second);
    ScratchDir tmp;
    const std::string cfg = write_text(tmp / "cfg.toml", config_of(kind->name(), kind->example()));
    const RunSummary s = run_quiet(cfg, tmp / "out");
    REQUIRE(s.failed == 0);
    const auto rows = read_results_csv(tmp / "out/results.csv");
    REQUIRE(rows.size() == 1);
    const Row& row = rows[0];
    CHECK(row.at("method") == kind->name());
    CHECK(row.at("status") == "ok");
    for (const auto& col : kind->columns()) {
      INFO(col);
      CHECK(!row.at(col).empty());
    }
    for (const char* col : {"rel_mse", "cos_rmse", "storage_floats", "samples"}) CHECK(!row.at(col).empty());
    CHECK(row.at("seed").empty() == !kind->seeded());
  }
}

// docs/experiments.md's copy of these tables is written and checked by
// scripts/gen-docs.py (CTest "docs: generated tables are the commands' output").
TEST_CASE("catalogue: brdf-factor list methods prints the catalogue's key tables") {
  std::string out;
  REQUIRE(run_cli("list methods", &out) == 0);
  CHECK(out == method_key_tables());
}

TEST_CASE("catalogue: a range in a kind's key spec is the range the reader enforces") {
  // sh-k order: the spec's range (ShkOptions::kMaxOrder) is the reader's and the docs'.
  const std::vector<KeySpec> keys = find_method_kind("sh-k")->keys();  // by value: keep it alive
  const KeySpec& order = find_key(keys, "order");
  CHECK(order.int_hi == ShkOptions::kMaxOrder);
  CHECK(order.type_cell().find("0.." + std::to_string(ShkOptions::kMaxOrder)) != std::string::npos);
  require_one_config_error(std::string(kConfigHead) + "[[method]]\nkind = \"sh-k\"\norder = " +
                               std::to_string(ShkOptions::kMaxOrder + 1) + "\n",
                           {"cfg.toml:", "method[0].order:", "0.." + std::to_string(ShkOptions::kMaxOrder)});
  // A validate() failure that names its field is reported at that key's line.
  require_one_config_error(std::string(kConfigHead) + "[[method]]\nkind = \"model-fit\"\nmodel = \"ward\"\n\nlobes = 2\n",
                           {"cfg.toml:14: method[0].lobes:", "lafortune"});
}

namespace {

// A toy kind: the BRDF's mean over the samples as a constant (one RGB triple).
class ConstantFactorization final : public Factorization {
 public:
  explicit ConstantFactorization(Rgb c) : c_(c) {}
  Rgb eval(const Vec3& wi, const Vec3& wo) const override {
    return wi.z() > 0 && wo.z() > 0 ? c_ : Rgb::Zero();
  }
  std::string name() const override { return "constant"; }
  std::string to_string() const override { return "constant"; }
  std::string method() const override { return "toy-constant"; }
  size_t storage_floats() const override { return 3; }
  nlohmann::json describe() const override { return {{"method", "toy-constant"}, {"rgb", {c_[0], c_[1], c_[2]}}}; }

 private:
  Rgb c_;
};

class ToyConstantKind final : public MethodKind {
 public:
  std::string name() const override { return "toy-constant"; }
  std::string summary() const override { return "The samples' mean value (a test kind)."; }
  std::vector<KeySpec> keys() const override {
    return {num_key("scale", 0.0, 10.0, true, "1", "multiplies the mean")};
  }
  std::string example() const override { return "scale = 2\n"; }
  std::vector<std::string> described() const override { return {"scale"}; }
  std::vector<std::string> columns() const override { return {"terms"}; }
  void read(Reader& r, MethodVariant& m, nlohmann::json& o, uint64_t) const override {
    const double scale = r.number(keys()[0], 1.0);
    o["scale"] = scale;
    kind_options<double>(m) = scale;
  }
  MethodOutcome run(const RunContext& c) const override {
    Rgb sum = Rgb::Zero();
    double n = 0;
    for (size_t i = 0; i < c.samples.size(); ++i)
      if (c.samples.valid[i]) sum += c.samples.value[i], n += 1;
    MethodOutcome out;
    out.result = std::make_shared<ConstantFactorization>(sum / n * kind_options<double>(c.method));
    return out;
  }
  void fill_row(const RunContext&, MethodOutcome&, Row& row) const override { row["terms"] = "1"; }
};

}  // namespace

TEST_CASE("catalogue: a kind added at run time needs only its class and one registration line") {
  register_method_kind(std::make_shared<ToyConstantKind>());
  struct Unregister {
    ~Unregister() { unregister_method_kind("toy-constant"); }
  } unregister;
  CHECK_THROWS_WITH(register_method_kind(std::make_shared<ToyConstantKind>()),
                    Catch::Contains("already registered"));
  ScratchDir tmp;
  // Read, validated (its range), hashed, run, scored, exported, described.
  require_one_config_error(config_of("toy-constant", "scale = 20\n"),
                           {"method[0].scale:", "(0, 10]", "found 20"});
  require_one_config_error(config_of("toy-constant", "scale = 2\nterms = 3\n"),
                           {"method[0].terms:", "does not apply to kind = \"toy-constant\""});
  const std::string cfg = write_text(tmp / "cfg.toml", config_of("toy-constant", "scale = [1, 2]\n"));
  const RunSummary s = run_quiet(cfg, tmp / "out");
  REQUIRE(s.executed == 2);
  const auto rows = read_results_csv(tmp / "out/results.csv");
  REQUIRE(rows.size() == 2);
  CHECK(rows[0].at("method") == "toy-constant");
  CHECK(rows[0].at("terms") == "1");
  CHECK(rows[0].at("storage_floats") == "3");
  CHECK(rows[0].at("run_id") != rows[1].at("run_id"));
  CHECK(rows[0].at("rel_mse") != rows[1].at("rel_mse"));  // the scale changes the fit
  CHECK(fs::exists(fs::path(tmp / "out/runs") / rows[0].at("run_id") / "factorization.json"));
  CHECK(method_key_tables().find("#### `kind = \"toy-constant\"`") != std::string::npos);
}
