// Symmetries as data (brdfs/symmetry.h): what models claim holds at symmetric
// pairs, what readers declare, what an interpolant claims, and the orbit
// expansion of raw samples.
#include "brdfs/symmetry.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "brdfs/catalogue.h"
#include "brdfs/directions.h"
#include "brdfs/measured.h"
#include "brdfs/merl.h"
#include "brdfs/sample_csv.h"
#include "brdfs/sampleset.h"
#include "test_common.h"

using namespace bf;

namespace {

Vec3 rot_z(const Vec3& v, double a) {
  return Vec3(std::cos(a) * v.x() - std::sin(a) * v.y(), std::sin(a) * v.x() + std::cos(a) * v.y(), v.z());
}
Vec3 mirror(const Vec3& v) { return Vec3(v.x(), -v.y(), v.z()); }
bool close(const Rgb& a, const Rgb& b) { return ((a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()))).all(); }

// Symmetries that hold numerically at 200 random pairs (each tested alone).
Symmetries measured_symmetries(const Brdf& b) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  Symmetries s = Symmetries::all();
  for (int k = 0; k < 200; ++k) {
    const Vec3 wi = from_spherical(std::acos(U(rng)), 2 * M_PI * U(rng));
    const Vec3 wo = from_spherical(std::acos(U(rng)), 2 * M_PI * U(rng));
    const Rgb f = b.eval(wi, wo);
    const double a = 2 * M_PI * U(rng);
    if (!close(b.eval(rot_z(wi, a), rot_z(wo, a)), f)) s.isotropic = false;
    if (!close(b.eval(wo, wi), f)) s.reciprocal = false;
    if (!close(b.eval(mirror(wi), mirror(wo)), f)) s.bilateral = false;
  }
  return s;
}

}  // namespace

TEST_CASE("symmetry: every catalogue BRDF's claimed symmetries hold at symmetric pairs") {
  const Catalogue& cat = Catalogue::builtin();
  std::vector<std::string> specs;
  for (const auto& [name, m] : cat.models()) specs.push_back(name);
  for (const auto& [name, p] : cat.presets()) specs.push_back(name);
  // Variants without some symmetry, so a wrong claim of the formula is probed too.
  for (const char* s : {"ward:ax=0.1,ay=0.3", "ashikhmin-shirley:nu=10,nv=200", "lafortune:cx0=-1,cy0=-0.5,cz0=0.9,n0=8",
                        "separable:a2=0.4", "mccool-form:q4=0.5"})
    specs.push_back(s);
  int without_bilateral = 0;
  for (const auto& spec : specs) {
    BrdfPtr b;
    try {
      b = cat.make(spec);
    } catch (const std::exception& e) {
      FAIL_CHECK(spec << ": " << e.what());
      continue;
    }
    const Symmetries claimed = symmetries_of(*b);
    const Symmetries holds = measured_symmetries(*b);
    INFO(spec << " claims " << claimed.to_string() << ", holds " << holds.to_string());
    CHECK(holds.covers(claimed));
    without_bilateral += !holds.bilateral;
  }
  CHECK(without_bilateral >= 2);  // the probe sees a broken mirror symmetry: it can fail
}

TEST_CASE("symmetry: parse and print round-trip, bad names are errors naming the key") {
  CHECK(parse_symmetries("none", "k") == Symmetries::none());
  CHECK(parse_symmetries("isotropic+bilateral", "k") == Symmetries{true, false, true});
  CHECK(parse_symmetries(Symmetries::all().to_string(), "k") == Symmetries::all());
  for (const char* bad : {"", "isotropic+", "iso", "reciprocal+reciprocal", "none+isotropic"}) {
    INFO(bad);
    try {
      parse_symmetries(bad, "sampling.symmetries");
      FAIL("accepted");
    } catch (const std::invalid_argument& e) {
      CHECK(std::string(e.what()).find("sampling.symmetries") != std::string::npos);
      CHECK(std::string(e.what()).find("found") != std::string::npos);
    }
  }
}

TEST_CASE("symmetry: readers declare what their format guarantees") {
  const BrdfPtr k = Catalogue::builtin().make("krylon-blue");
  CHECK(measured_samples(*k).symmetries == Symmetries::all());
  CHECK(k->isotropic());
  CHECK(k->whole_domain());
  const BrdfPtr m = Catalogue::builtin().make("mystique");
  CHECK(measured_samples(*m).symmetries == Symmetries::all());
  // MERL cells: isotropic + reciprocal (phi_d folded by reciprocity only).
  const MerlBrdf merl(std::make_shared<const MerlTable>(merl_tabulate(*Catalogue::builtin().make("lambert"))),
                      MerlLookup::Nearest, "lambert.binary");
  CHECK(merl.samples(30).symmetries == Symmetries{true, true, false});
  CHECK(merl.whole_domain());
}

TEST_CASE("symmetry: an interpolant of a CSV claims no symmetry its data do not declare") {
  // A planted anisotropic, non-reciprocal list: f depends on wi.x only.
  const bf_test::TempDir dir("symmetry_csv");
  const std::string path = dir.file("aniso.csv");
  SampleSet s;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int k = 0; k < 200; ++k) {
    const Vec3 wi = from_spherical(std::acos(U(rng)), 2 * M_PI * U(rng));
    const Vec3 wo = from_spherical(std::acos(U(rng)), 2 * M_PI * U(rng));
    s.push(wi, wo, Rgb::Constant(0.1 + 0.5 * (1 + wi.x())));
  }
  write_sample_csv(s, path);
  CHECK(read_sample_csv(path).symmetries == Symmetries::none());
  const BrdfPtr b = Catalogue::builtin().make(path);
  CHECK_FALSE(b->isotropic());
  CHECK_FALSE(b->reciprocal());
  CHECK_FALSE(b->bilateral());
  std::string why;
  CHECK_FALSE(b->whole_domain(&why));
  CHECK(why.find("declare none") != std::string::npos);
  // Declared by the data: the claims follow.
  SampleSet declared = read_sample_csv(path);
  declared.symmetries = Symmetries::all();
  const MeasuredBrdf d("csv", declared, MeasuredOptions{});
  CHECK(d.isotropic());
  CHECK(d.whole_domain());
}

TEST_CASE("symmetry: an orbit of samples changes nothing for a BRDF that has the symmetry") {
  const BrdfPtr ct = Catalogue::builtin().make("cook-torrance");
  REQUIRE(symmetries_of(*ct) == Symmetries::all());
  SampleSet s = sample_stratified(*ct, 300, 5);
  s.weight.assign(s.size(), 0.0);
  for (size_t k = 0; k < s.size(); ++k) s.weight[k] = 0.5 + (k % 3);
  OrbitInfo info;
  const SampleSet o = expand_orbit(s, Symmetries::all(), {24, 2'000'000}, &info);
  CHECK(info.rotations == 24);
  CHECK(info.orbit_size == 96);
  REQUIRE(o.size() == 96 * s.size());
  double w_in = 0, w_out = 0;
  for (size_t k = 0; k < s.size(); ++k) w_in += s.weight[k];
  size_t differ = 0;
  for (size_t k = 0; k < o.size(); ++k) {
    w_out += o.weight_of(k);
    if (!close(ct->eval(o.wi[k], o.wo[k]), o.value[k])) ++differ;
    // Each measured sample keeps its total weight.
    if (k % 96 == 0) {
      double wk = 0;
      for (size_t j = k; j < k + 96; ++j) wk += o.weight[j];
      CHECK(wk == Approx(s.weight[k / 96]).epsilon(1e-12));
    }
  }
  CHECK(differ == 0);
  CHECK(w_out == Approx(w_in).epsilon(1e-12));
  // The same orbit of an anisotropic BRDF's samples does change values: the check can fail.
  const BrdfPtr sep = Catalogue::builtin().make("separable");
  REQUIRE_FALSE(sep->isotropic());
  const SampleSet so = expand_orbit(sample_stratified(*sep, 100, 5), {true, false, false}, {8, 2'000'000});
  size_t changed = 0;
  for (size_t k = 0; k < so.size(); ++k) changed += !close(sep->eval(so.wi[k], so.wo[k]), so.value[k]);
  CHECK(changed > so.size() * 3 / 4);
}

TEST_CASE("symmetry: the orbit's rotations follow the budget and masked samples are dropped") {
  const BrdfPtr l = Catalogue::builtin().make("lambert");
  SampleSet s = sample_stratified(*l, 100, 1);
  s.value[3] = Rgb::Constant(-1.0);
  s.validate();
  OrbitInfo info;
  SampleSet o = expand_orbit(s, Symmetries::all(), {24, 1000}, &info);
  CHECK(info.rotations == 2);  // floor(1000 / (99 * 4))
  CHECK(o.size() == 99 * 8);
  CHECK(o.valid_count() == o.size());
  o = expand_orbit(s, {true, true, false}, {24, 10}, &info);
  CHECK(info.rotations == 1);  // at least one rotation, whatever the budget
  CHECK(o.size() == 99 * 2);
  o = expand_orbit(s, Symmetries::none(), {}, &info);
  CHECK(o.size() == 99);
  CHECK(o.symmetries == Symmetries::none());
}
