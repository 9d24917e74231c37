// Config parsing, validation messages, sweep expansion and -D overrides.
#include <algorithm>

#include "experiments/config/config.h"
#include "experiments/methods/homomorphic.h"
#include "factor/svd_baseline.h"
#include "experiments/methods/method_kind.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {

const char* const kBase = kConfigHead;

Plan plan_of(const std::string& text, std::vector<std::string> defines = {}) {
  register_loaders();
  return parse_plan(text, "cfg.toml", defines);
}

std::string all(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& m : v) s += m + "\n";
  return s;
}

}  // namespace

TEST_CASE("config: a valid config expands to brdf x sampling x method runs") {
  const Plan p = plan_of(std::string(kBase) + R"(
[[method]]
kind = "mccool"
[[method]]
kind = "search"
terms = 1
restarts = 1
)");
  REQUIRE(p.runs.size() == 2);
  CHECK(p.experiment.name == "t");
  CHECK(p.experiment.out == "results/t");
  CHECK(p.methods[0].kind == "mccool");
  CHECK(homomorphic_options(p.methods[1]).search.restarts == 1);
  CHECK(p.methods[1].seed == 1);  // experiment.seed by default
  CHECK(p.runs[0].run_id.size() == 12);
  CHECK(p.runs[0].run_id != p.runs[1].run_id);
}

TEST_CASE("config: each rule broken gives one message with file:line, field and rule") {
  SECTION("TOML syntax") { require_one_config_error("[experiment\nname = 1\n", {"cfg.toml:1:", "TOML"}); }
  SECTION("unknown section") {
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = \"mccool\"\n[samplin]\nx = 1\n",
                {"cfg.toml:", "samplin", "unknown section", "did you mean 'sampling'"});
  }
  SECTION("unknown key, with a suggestion") {
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = \"search\"\nrestrats = 2\n",
                {"cfg.toml:12: method[0].restrats: unknown key", "did you mean 'restarts'"});
  }
  SECTION("a key of another kind") {
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = \"mccool\"\nrestarts = 2\n",
                {"cfg.toml:12: method[0].restarts: does not apply to kind = \"mccool\"", "search"});
  }
  SECTION("wrong type") {
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = \"search\"\nterms = \"two\"\n",
                {"cfg.toml:12: method[0].terms: expected an integer in 1..64, found \"two\" (a string)"});
  }
  SECTION("out of range") {
    require_one_config_error("[[brdf]]\npreset = \"bluepaint\"\n[sampling]\nresolution = 1\n[[method]]\nkind = \"mccool\"\n",
                {"cfg.toml:4: sampling.resolution: expected an integer in 2..64, found 1"});
  }
  SECTION("float out of range") {
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = \"mccool\"\neps = 0\n",
                {"cfg.toml:12: method[0].eps: expected a number in (0, 1], found 0"});
  }
  SECTION("unknown choice") {
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = \"search\"\nparameterization = \"halfdif\"\n",
                {"cfg.toml:12: method[0].parameterization: expected one of \"wiwo\", \"halfdiff\"",
                 "did you mean 'halfdiff'"});
  }
  SECTION("missing file") {
    require_one_config_error("[[brdf]]\nfile = \"no/such/file.astm\"\n[[method]]\nkind = \"mccool\"\n",
                {"cfg.toml:2: brdf[0].file: file not found"});
  }
  SECTION("missing sample file") {
    require_one_config_error("[[brdf]]\npreset = \"bluepaint\"\n[sampling]\nkind = \"file\"\npath = \"nope.csv\"\n"
                "[[method]]\nkind = \"mccool\"\n",
                {"cfg.toml:5: sampling.path: file not found"});
  }
  SECTION("contradiction: preset and model") {
    require_one_config_error("[[brdf]]\npreset = \"bluepaint\"\nmodel = \"lafortune\"\n[[method]]\nkind = \"mccool\"\n",
                {"cfg.toml:3: brdf[0].model: preset, model and file are alternatives"});
  }
  SECTION("contradiction: svd eps without log") {
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = \"svd\"\neps = 0.01\n",
                {"cfg.toml:12: method[0].eps: eps applies only to the log-space SVD"});
  }
  SECTION("contradiction: a grid with a count") {
    require_one_config_error("[[brdf]]\npreset = \"bluepaint\"\n[sampling]\nkind = \"grid\"\ncount = 100\n"
                "[[method]]\nkind = \"mccool\"\n",
                {"cfg.toml:5: sampling.count: does not apply to kind = \"grid\""});
  }
  SECTION("contradiction: measured samples of an analytic BRDF") {
    require_one_config_error("[[brdf]]\npreset = \"bluepaint\"\n[sampling]\nkind = \"measured\"\n[[method]]\nkind = \"mccool\"\n",
                {"cfg.toml:3: sampling.kind:", "not measured"});
  }
  SECTION("contradiction: sh-r order without view_order") {
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = \"sh-r\"\norder = 4\n",
                {"cfg.toml:12: method[0].order: fixed orders need both order and view_order"});
  }
  SECTION("contradiction: fit terms beyond the projections") {
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = \"fit\"\nprojections = [{ name = \"wi\" }]\nterms = 2\n",
                {"cfg.toml:13: method[0].terms: terms = 2 but only 1 projections"});
  }
  SECTION("contradiction: a named projection in the wrong parameterization") {
    require_one_config_error(std::string(kBase) +
                    "[[method]]\nkind = \"fit\"\nprojections = [{ name = \"h\", parameterization = \"wiwo\" }]\n",
                {"cfg.toml:12: method[0].projections[0].name:", "halfdiff projection"});
  }
  SECTION("a projection matrix that is not orthonormal") {
    require_one_config_error(std::string(kBase) +
                    "[[method]]\nkind = \"fit\"\nprojections = [{ matrix = [[1, 1, 0, 0], [0, 0, 1, 0]] }]\n",
                {"cfg.toml:12: method[0].projections[0].matrix:", "orthonormal"});
  }
  SECTION("refine on a kind that is not homomorphic") {
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = \"svd\"\nrefine = \"linear\"\n",
                {"cfg.toml:12: method[0].refine:", "homomorphic kinds"});
  }
  SECTION("tolerance where the method does not support it") {
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = \"model-fit\"\nmodel = \"ward\"\n"
                             "tolerance = { metric = \"rel_mse\", value = 0.1 }\n",
                {"cfg.toml:13: method[0].tolerance: does not apply to kind = \"model-fit\""});
  }
  SECTION("a bad tolerance metric") {
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = \"svd\"\ntolerance = { metric = \"rmse\", value = 0.1 }\n",
                {"cfg.toml:12: method[0].tolerance.metric: expected one of"});
  }
  SECTION("search with nothing to start from") {
    // The greedy search starts only from restarts and guesses (the structured
    // one, the default, also from the data's Hessians, so restarts = 0 is valid there).
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = \"search\"\nstrategy = \"greedy\"\nrestarts = 0\n",
                {"cfg.toml:13: method[0].restarts:", "nothing to search from"});
  }
  SECTION("unknown BRDF parameter, at its own line") {
    require_one_config_error("[[brdf]]\nmodel = \"blinn-phong\"\nn = 10\nshininess = 3\n[[method]]\nkind = \"mccool\"\n",
                {"cfg.toml:4: brdf[0].shininess:", "shininess"});
  }
  SECTION("unknown preset") {
    require_one_config_error("[[brdf]]\npreset = \"bluepaynt\"\n[[method]]\nkind = \"mccool\"\n",
                {"cfg.toml:2: brdf[0].preset: unknown preset \"bluepaynt\"", "did you mean 'bluepaint'"});
  }
  SECTION("no method") { require_one_config_error(kBase, {"cfg.toml: method: missing"}); }
  SECTION("a method kind cannot be swept") {
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = [\"mccool\", \"svd\"]\n",
                {"cfg.toml:11: method[0].kind: cannot be a sweep"});
  }
  SECTION("an empty sweep") {
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = \"mccool\"\ntexture_size = []\n",
                {"cfg.toml:12: method[0].texture_size:", "empty array"});
  }
}

TEST_CASE("config: every problem is reported, each once") {
  const auto errs = config_errors(std::string(kBase) + R"(
[[method]]
kind = "search"
terms = 0
restarts = -1
texture_size = [4, 1, 8]
)");
  INFO(all(errs));
  REQUIRE(errs.size() == 3);
  CHECK(errs[0].find("method[0].") != std::string::npos);
  // The bad texture_size appears in two of the three sweep variants but is reported once.
  CHECK(std::count_if(errs.begin(), errs.end(), [](const std::string& m) {
          return m.find("texture_size") != std::string::npos;
        }) == 1);
}

TEST_CASE("config: sweeps expand as a cartesian product in file order") {
  const Plan p = plan_of(std::string(kBase) + R"(
[[method]]
kind = "search"
parameterization = ["wiwo", "halfdiff"]
terms = [1, 2, 3]
restarts = 1
)");
  REQUIRE(p.methods.size() == 6);
  REQUIRE(p.runs.size() == 6);
  // parameterization comes first in the file: it is the outer loop.
  CHECK(homomorphic_options(p.methods[0]).param == Parameterization::WiWo);
  CHECK(p.methods[0].terms == 1);
  CHECK(p.methods[2].terms == 3);
  CHECK(homomorphic_options(p.methods[3]).param == Parameterization::HalfDiff);
  CHECK(p.methods[3].terms == 1);
}

TEST_CASE("config: zip advances lists together") {
  const Plan p = plan_of(std::string(kBase) + R"(
[[method]]
kind = "svd"
terms = [1, 2, 4]
texture_size = [8, 12, 16]
parameterization = ["wiwo", "halfdiff"]
zip = ["terms", "texture_size"]
)");
  REQUIRE(p.methods.size() == 6);
  CHECK(p.methods[0].terms == 1);
  CHECK(p.methods[0].texture_size == 8);
  CHECK(kind_options<SvdOptions>(p.methods[0]).param == Parameterization::WiWo);
  CHECK(p.methods[1].terms == 1);
  CHECK(kind_options<SvdOptions>(p.methods[1]).param == Parameterization::HalfDiff);
  CHECK(p.methods[4].terms == 4);
  CHECK(p.methods[4].texture_size == 16);
  SECTION("unequal lengths are an error") {
    require_one_config_error(std::string(kBase) + R"(
[[method]]
kind = "svd"
terms = [1, 2]
texture_size = [8, 12, 16]
zip = ["terms", "texture_size"]
)",
                {"cfg.toml:15: method[0].zip: zipped lists must have equal lengths"});
  }
  SECTION("zip names a key that is not a sweep") {
    require_one_config_error(std::string(kBase) + "[[method]]\nkind = \"svd\"\nterms = 2\ntexture_size = [8, 16]\n"
                                     "zip = [\"terms\", \"texture_size\"]\n",
                {"method[0].zip: 'terms' is not a sweep"});
  }
}

TEST_CASE("config: sweeps of BRDFs, their parameters and sampling") {
  const Plan p = plan_of(R"(
[[brdf]]
preset = ["bluepaint", "clay"]
[[brdf]]
model = "blinn-phong"
n = { sweep = [10, 40] }
kd = [0.1, 0.2, 0.3]
[sampling]
kind = ["grid", "stratified"]
resolution = 6
count = 500
[[method]]
kind = "mccool"
)");
  REQUIRE(p.brdfs.size() == 4);
  CHECK(p.brdfs[0].label == "bluepaint");
  CHECK(p.brdfs[2].label == "blinn-phong:kd=0.1/0.2/0.3,n=10");
  REQUIRE(p.samplings.size() == 2);
  CHECK(p.samplings[0].label == "grid 6^4");
  CHECK(p.samplings[1].label == "stratified 500 seed 1");
  CHECK(p.runs.size() == 8);
}

TEST_CASE("config: -D overrides any value") {
  const std::string text = std::string(kBase) + R"(
[[method]]
kind = "mccool"
texture_size = 16
[[method]]
kind = "search"
restarts = 6
)";
  SECTION("a section key") {
    const Plan p = plan_of(text, {"sampling.resolution=4", "experiment.name=other"});
    CHECK(p.samplings[0].resolution == 4);
    CHECK(p.experiment.name == "other");
  }
  SECTION("method.KEY reaches every method that accepts KEY") {
    const Plan p = plan_of(text, {"method.restarts=1", "method.texture_size=8"});
    CHECK(p.methods[0].texture_size == 8);
    CHECK(p.methods[1].texture_size == 8);
    CHECK(homomorphic_options(p.methods[1]).search.restarts == 1);
  }
  SECTION("method[N].KEY reaches one method; a list becomes a sweep") {
    const Plan p = plan_of(text, {"method[1].terms=[1, 2]", "method[1].parameterization=halfdiff"});
    REQUIRE(p.methods.size() == 3);
    CHECK(p.methods[1].terms == 1);
    CHECK(p.methods[2].terms == 2);
    CHECK(homomorphic_options(p.methods[2]).param == Parameterization::HalfDiff);
  }
  SECTION("a new section") {
    const Plan p = plan_of(text, {"scene.size=32"});
    CHECK(p.scene.named);
    CHECK(p.scene.size == 32);
  }
  SECTION("a nested key") {
    const Plan p = plan_of(std::string(kBase) + "[[method]]\nkind = \"svd\"\n"
                                                "tolerance = { metric = \"rel_mse\", value = 0.5 }\n",
                           {"method[0].tolerance.value=0.1"});
    REQUIRE(p.methods[0].tolerance);
    CHECK(p.methods[0].tolerance->value == 0.1);
  }
  SECTION("a bad overridden value is reported at the -D") {
    require_one_config_error(text, {"-D sampling.resolution=1: sampling.resolution: expected an integer in 2..64, found 1"},
                {"sampling.resolution=1"});
  }
  SECTION("a key no method accepts") {
    require_one_config_error(text, {"-D method.order=3: method.order: no [[method]] of this config accepts 'order'"},
                {"method.order=3"});
  }
  SECTION("malformed") {
    require_one_config_error(text, {"-D nonsense: -D: expected key=value"}, {"nonsense"});
    require_one_config_error(text, {"-D methd.x=1: methd.x: unknown section"}, {"methd.x=1"});
    require_one_config_error(text, {"method[5].terms: index 5 out of range"}, {"method[5].terms=1"});
  }
}

TEST_CASE("config: run ids hash what determines a run, and only that") {
  const std::string text = std::string(kBase) + R"(
[[method]]
kind = "mccool"
[[method]]
kind = "search"
terms = 1
restarts = 1
)";
  const Plan a = plan_of(text), b = plan_of(text);
  CHECK(a.runs[0].run_id == b.runs[0].run_id);
  CHECK(a.plan_hash == b.plan_hash);
  // A label or the thread count do not change results.
  const Plan c = plan_of(text, {"method[1].label=renamed", "method[1].threads=1"});
  CHECK(c.runs[1].run_id == a.runs[1].run_id);
  // An option does, for that method only; so does the sampling, for all.
  const Plan d = plan_of(text, {"method[1].seed=2"});
  CHECK(d.runs[0].run_id == a.runs[0].run_id);
  CHECK(d.runs[1].run_id != a.runs[1].run_id);
  const Plan e = plan_of(text, {"sampling.resolution=8"});
  CHECK(e.runs[0].run_id != a.runs[0].run_id);
  // Identical combinations are kept once.
  const Plan f = plan_of(text, {"method[0].texture_size=[16, 16]"});
  CHECK(f.runs.size() == 2);
  CHECK(f.duplicates == 1);
}

TEST_CASE("config: every key is documented in docs/experiments.md") {
  const std::string doc = read_text(source_path("docs/experiments.md"));
  REQUIRE(!doc.empty());
  std::vector<std::string> sections = {"top", "experiment", "sampling", "scene", "brdf", "projection", "tolerance"};
  for (const auto& kind : method_kind_names()) sections.push_back("method:" + kind);  // every registered kind
  for (const auto& section : sections)
    for (const auto& key : config_keys(section)) {
      INFO(section << "." << key);
      CHECK(doc.find("`" + key + "`") != std::string::npos);
    }
}

TEST_CASE("config: the CLI prints one line per problem and exits 2") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "bad.toml", std::string(kBase) +
                                                           "[[method]]\nkind = \"search\"\nterms = 0\n"
                                                           "restrats = 1\n");
  std::string out;
  const int code = run_cli("run " + cfg + " --out " + (tmp / "out"), &out);
  CHECK(code == 2);
  INFO(out);
  CHECK(out.find("brdf-factor: " + cfg + ":12: method[0].terms: expected an integer in 1..64, found 0\n") !=
        std::string::npos);
  CHECK(out.find("brdf-factor: " + cfg + ":13: method[0].restrats: unknown key") != std::string::npos);
  CHECK(!fs::exists(tmp / "out"));  // nothing written
}

TEST_CASE("config: non-greedy search keys (beam, backfit) are read, validated, and keep greedy run ids") {
  const std::string greedy = std::string(kBase) + "[[method]]\nkind = \"search\"\nstrategy = \"greedy\"\nrestarts = 3\n";
  const Plan g = plan_of(greedy);
  // Without a strategy, a greedy-only key selects the greedy search (the default is "structured").
  CHECK(homomorphic_options(plan_of(std::string(kBase) + "[[method]]\nkind = \"search\"\nrestarts = 3\n").methods[0]).search.strategy ==
        "structured");
  CHECK(homomorphic_options(plan_of(std::string(kBase) + "[[method]]\nkind = \"search\"\nbeam = 1\n").methods[0]).search.strategy ==
        "greedy");
  const Plan g1 = plan_of(greedy + "beam = 1\nbackfit_sweeps = 0\n");
  CHECK(g.runs[0].run_id == g1.runs[0].run_id);  // defaults do not change the id (cache kept)
  const Plan p = plan_of(greedy + "beam = 2\nbackfit_sweeps = [0, 3]\nbackfit_restarts = 1\n");
  REQUIRE(p.methods.size() == 2);
  CHECK(homomorphic_options(p.methods[0]).search.beam == 2);
  CHECK(homomorphic_options(p.methods[1]).search.backfit_sweeps == 3);
  CHECK(homomorphic_options(p.methods[1]).search.backfit_restarts == 1);
  CHECK(p.runs[0].run_id != g.runs[0].run_id);
  CHECK(p.runs[0].run_id != p.runs[1].run_id);
  require_one_config_error(greedy + "beam = 4\n", {"cfg.toml:", "method[0]", "beam", "1..3", "found 4"});
  require_one_config_error(greedy + "backfit_sweeps = -1\n", {"cfg.toml:", "method[0].backfit_sweeps", "found -1"});
}

TEST_CASE("config: a kind's typed options are its own and another kind's type is refused naming the method") {
  const Plan p = plan_of(std::string(kBase) + "[[method]]\nkind = \"svd\"\nterms = 3\nlabel = \"mine\"\n");
  CHECK(kind_options<SvdOptions>(p.methods[0]).rank == 3);
  try {
    (void)homomorphic_options(p.methods[0]);
    FAIL("reading svd's options as HomomorphicOptions did not throw");
  } catch (const std::logic_error& e) {
    const std::string what = e.what();
    CHECK(what.find("mine") != std::string::npos);
    CHECK(what.find("svd") != std::string::npos);
    CHECK(what.find("another type") != std::string::npos);
  }
  MethodVariant empty;
  empty.kind = "svd";
  CHECK_THROWS_AS(kind_options<SvdOptions>(static_cast<const MethodVariant&>(empty)), std::logic_error);
}
