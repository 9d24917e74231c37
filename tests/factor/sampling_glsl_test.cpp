// The exported sampler (factor/sampling_export.h): its GLSL compiles for the
// four targets, and executed on llvmpipe, brdf_factor_sample and
// brdf_factor_pdf agree with the CPU sampler on 1,000 (wo, u) pairs to 1e-4;
// the exported texture and sidecar entry reload into the same sampler.
#include <filesystem>
#include <random>

#include "brdfs/catalogue.h"
#include "factor/glsl_compile.h"
#include "factor/glsl_run.h"
#include "factor/sampling.h"
#include "factor/sampling_export.h"
#include "test_common.h"

using namespace bf;
using namespace bf_test;
namespace fs = std::filesystem;

namespace {

struct Tmp {
  fs::path path;
  Tmp() {
    path = fs::temp_directory_path() / ("bf_sampling_glsl_" + std::to_string(::getpid()));
    fs::create_directories(path);
  }
  ~Tmp() {
    if (!std::getenv("BF_KEEP_TMP")) fs::remove_all(path);
  }
};

std::string wrapper(const char* body) {
  return std::string("vec3 brdf_factor_eval(vec3 a, vec3 wo) {\n") + body + "\n}\n";
}

// Runs the exported GLSL of f's tabulated sampler on llvmpipe at 1,000 (wo, u)
// pairs (float-exact, wo over the whole hemisphere: 20 on the normal, 20 at
// cos theta_o = 0.02, the rest uniform in cos theta_o and phi_o) and checks:
// wi agrees with the CPU's to 1e-4 in every component (absolute: wi is a unit
// vector, so that is about 1e-4 rad; a relative bound on a component near 0
// would ask float32 for more than its 6e-8), the pdf returned by
// brdf_factor_sample and brdf_factor_pdf at the GPU's wi agree with the CPU's
// to 1e-4 relative. BF_KEEP_TMP=1 keeps the shader, texture and outputs
// (cpu.txt beside out.txt) for debugging.
void check_glsl_sampler_on_llvmpipe(const std::string& spec, SamplerOptions so) {
  INFO(spec);
  const BrdfPtr f = Catalogue::builtin().make(spec);
  so.method = "tabulated";
  const auto s = make_sampler(*f, so);
  Tmp tmp;
  const nlohmann::json entry = write_sampling_export(*s, tmp.path.string());
  const std::string glsl = slurp((tmp.path / "sampling.glsl").string());
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  std::vector<std::pair<Vec3, Vec3>> pairs;  // (u1, u2, 0), wo
  for (int k = 0; k < 1000; ++k) {
    const double ct = k < 20 ? 1.0 : k < 40 ? 0.02 : uni(rng), ph = 2 * M_PI * uni(rng);
    const double st = std::sqrt(1 - ct * ct);
    Eigen::Vector3f wo(float(st * std::cos(ph)), float(st * std::sin(ph)), float(ct));
    pairs.push_back({Vec3(uni(rng), uni(rng), 0), wo.cast<double>()});
  }
  std::vector<DirectionSample> cpu;
  {
    std::ofstream out(tmp.path / "cpu.txt");
    out.precision(9);
    for (const auto& [u, wo] : pairs) {
      cpu.push_back(s->sample(wo, u.x(), u.y()));
      const DirectionSample& d = cpu.back();
      out << d.wi.x() << " " << d.wi.y() << " " << d.wi.z() << " " << d.pdf << "\n";
    }
  }
  const std::vector<std::pair<std::string, std::string>> tex = {
      {"brdf_factor_sampling", (tmp.path / "sampling.exr").string()}};
  // wi: run, then compare absolutely with the GPU's values the run wrote.
  const fs::path gw = tmp.path / "wi.glsl", gp = tmp.path / "pdf.glsl";
  std::ofstream(gw) << glsl << wrapper("return brdf_factor_sample(wo, a.xy).xyz;");
  size_t k = 0;
  glsl_run_error(gw.string(), pairs, tex, [&](const Vec3&, const Vec3&) -> Rgb { return cpu[k++].wi.array(); },
                 tmp.path);
  std::ifstream gpu(tmp.path / "out.txt");
  double e_wi = 0;
  int bad = 0;
  for (const DirectionSample& d : cpu) {
    Vec3 g;
    REQUIRE(gpu >> g[0] >> g[1] >> g[2]);
    const double e = (g - d.wi).cwiseAbs().maxCoeff();
    e_wi = std::max(e_wi, e);
    bad += e > 1e-4;
  }
  INFO(bad << " of 1000 wi differ by more than 1e-4");
  CHECK(e_wi < 1e-4);
  std::ofstream(gp) << glsl << wrapper("vec4 s = brdf_factor_sample(wo, a.xy);\n"
                                       "return vec3(s.w, brdf_factor_pdf(s.xyz, wo), 0.0);");
  k = 0;
  const double e_pdf = glsl_run_error(
      gp.string(), pairs, tex,
      [&](const Vec3&, const Vec3& wo) -> Rgb {
        const DirectionSample& d = cpu[k++];
        return Rgb(d.pdf, s->pdf(d.wi, wo), 0.0);
      },
      tmp.path);
  CHECK(e_pdf < 1e-4);
}

}  // namespace

// One anisotropic BRDF (four view azimuth bins: every branch of the binning)
// at a small table, so that the default suite runs it.
TEST_CASE("sampling: exported GLSL sample and pdf match the CPU on llvmpipe", "[glsl][glsl-sampler]") {
  SamplerOptions so;
  so.view_bins = 8, so.theta_bins = 16, so.phi_bins = 32, so.cell_samples = 1, so.view_phi_bins = 4;
  check_glsl_sampler_on_llvmpipe("ward:ax=0.1,ay=0.3", so);
}

// Three BRDFs (a measured-like Lafortune, a glossy Cook-Torrance, an
// anisotropic Ward) at the default table sizes (16 view azimuth bins for Ward).
TEST_CASE("sampling: exported GLSL sampler matches the CPU at default sizes for three BRDFs",
          "[glsl][glsl-sampler][slow]") {
  for (const char* spec : {"bluepaint", "cook-torrance:kd=0.1,ks=0.9,m=0.2,f0=0.1", "ward:ax=0.1,ay=0.3"}) {
    SamplerOptions so;
    check_glsl_sampler_on_llvmpipe(spec, so);
  }
}

// The exported sampling GLSL compiles for the four targets and its table
// reloads as the same sampler.
TEST_CASE("sampling: exported GLSL sample and pdf compile for four targets", "[glsl]") {
  const BrdfPtr f = Catalogue::builtin().make("cook-torrance:kd=0.1,ks=0.9,m=0.2,f0=0.1");
  SamplerOptions so;
  so.view_bins = 4, so.theta_bins = 8, so.phi_bins = 16, so.cell_samples = 1, so.method = "tabulated";
  const auto s = make_sampler(*f, so);
  Tmp tmp;
  const nlohmann::json entry = write_sampling_export(*s, tmp.path.string());
  CHECK(entry.at("storage_floats").get<size_t>() == s->storage_floats());
  const auto back = tabulated_sampler(
      sampling_table_from(read_exr((tmp.path / "sampling.exr").string()), entry, "sampling.exr"));
  for (const double ct : {1.0, 0.7, 0.17}) {
    const Vec3 wo(std::sqrt(1 - ct * ct), 0, ct);
    const DirectionSample a = s->sample(wo, 0.3, 0.8), b = back->sample(wo, 0.3, 0.8);
    CHECK(a.wi == b.wi);
    CHECK(a.pdf == b.pdf);
  }
  const std::string glsl = slurp((tmp.path / "sampling.glsl").string());
  const std::string err = compile_glsl_all_targets(glsl + wrapper("vec4 s = brdf_factor_sample(wo, a.xy);\n"
                                                                  "return vec3(s.w, brdf_factor_pdf(s.xyz, wo), 0.0);"),
                                                   tmp.path);
  INFO(err);
  CHECK(err.empty());
}
