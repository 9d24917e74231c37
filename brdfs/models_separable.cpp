// Synthetic product-form BRDFs (separable, mccool-form) built from smooth
// positive factors of parabolic coordinates, for planted-solution tests.
#include <cmath>

#include "brdfs/catalogue.h"
#include "brdfs/directions.h"
#include "brdfs/models.h"
#include "brdfs/models_internal.h"

namespace bf {

namespace {
ExpQuadratic make_eq(std::array<Rgb, 6> c) {
  ExpQuadratic e;
  e.c = c;
  return e;
}
Rgb rgb(double r, double g, double b) {
  return Rgb(r, g, b);
}
Rgb all(double v) {
  return Rgb::Constant(v);
}

void validate_eq(const std::string& model, char letter, const ExpQuadratic& e) {
  for (int i = 0; i < 6; ++i)
    detail::require(e.c[i].isFinite().all() && (e.c[i].abs() <= 50.0).all(), model,
                    std::string(1, letter) + std::to_string(i), detail::fmt(e.c[i]),
                    "in [-50, 50] (keeps the factor within double range)");
}

std::string eq_string(char letter, const ExpQuadratic& e) {
  std::string s;
  for (int i = 0; i < 6; ++i)
    s += std::string(i == 0 ? "" : ", ") + letter + std::to_string(i) + "=" + detail::fmt(e.c[i]);
  return s;
}

void read_eq(const ParamDict& d, char letter, ExpQuadratic& e) {
  for (int i = 0; i < 6; ++i)
    e.c[i] = d.get_rgb(std::string(1, letter) + std::to_string(i), e.c[i]);
}

void add_eq_docs(std::vector<ParamInfo>& params, char letter, const ExpQuadratic& e,
                 const std::string& what) {
  static const char* terms[6] = {"1", "u", "v", "u^2", "u v", "v^2"};
  for (int i = 0; i < 6; ++i)
    params.push_back({std::string(1, letter) + std::to_string(i), detail::fmt(e.c[i]),
                      what + ": coefficient of " + terms[i] + ", in [-50, 50]"});
}
}  // namespace

Rgb ExpQuadratic::eval(const Vec3& w) const {
  const Vec2 p = parabolic(w);
  const double u = p.x(), v = p.y();
  return (c[0] + c[1] * u + c[2] * v + c[3] * (u * u) + c[4] * (u * v) + c[5] * (v * v)).exp();
}

bool ExpQuadratic::rotation_invariant() const {
  return (c[1] == 0.0).all() && (c[2] == 0.0).all() && (c[4] == 0.0).all() && (c[3] == c[5]).all();
}

bool ExpQuadratic::operator==(const ExpQuadratic& o) const {
  for (int i = 0; i < 6; ++i)
    if ((c[i] != o.c[i]).any()) return false;
  return true;
}

// Defaults: every coefficient nonzero, channels differ in the constant term,
// factors peak inside the disk and fall off towards the rim; albedo < 1.
SeparableParams::SeparableParams()
    : a(make_eq({rgb(-1.0, -1.2, -1.4), all(0.3), all(-0.2), all(-0.5), all(0.15), all(-0.4)})),
      b(make_eq({rgb(-0.8, -0.9, -1.0), all(-0.25), all(0.2), all(-0.3), all(-0.1), all(-0.6)})),
      c(make_eq({rgb(0.5, 0.3, 0.1), all(0.1), all(-0.15), all(-2.0), all(0.3), all(-1.5)})) {}

void SeparableParams::validate() const {
  validate_eq("separable", 'a', a);
  validate_eq("separable", 'b', b);
  validate_eq("separable", 'c', c);
}

Separable::Separable(const SeparableParams& p) : p_(p) {
  p_.validate();
}

Rgb Separable::eval(const Vec3& wi, const Vec3& wo) const {
  if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
  const Vec3 h = (wi + wo).normalized();
  return p_.a.eval(wi) * p_.b.eval(wo) * p_.c.eval(h);
}

namespace {
bool even_in_v(const ExpQuadratic& q) { return (q.c[2] == 0.0).all() && (q.c[4] == 0.0).all(); }
}  // namespace

bool Separable::bilateral() const { return even_in_v(p_.a) && even_in_v(p_.b) && even_in_v(p_.c); }

bool McCoolForm::bilateral() const { return even_in_v(p_.p) && even_in_v(p_.q); }

bool Separable::isotropic() const {
  return p_.a.rotation_invariant() && p_.b.rotation_invariant() && p_.c.rotation_invariant();
}

std::string Separable::to_string() const {
  return "separable(" + eq_string('a', p_.a) + ", " + eq_string('b', p_.b) + ", " +
         eq_string('c', p_.c) + ")";
}

McCoolFormParams::McCoolFormParams()
    : p(make_eq({rgb(-0.6, -0.7, -0.8), all(0.2), all(-0.1), all(-0.5), all(0.1), all(-0.3)})),
      q(make_eq({rgb(0.1, -0.05, -0.2), all(-0.1), all(0.15), all(-2.5), all(0.2), all(-2.0)})) {}

void McCoolFormParams::validate() const {
  validate_eq("mccool-form", 'p', p);
  validate_eq("mccool-form", 'q', q);
}

McCoolForm::McCoolForm(const McCoolFormParams& p) : p_(p) {
  p_.validate();
}

Rgb McCoolForm::eval(const Vec3& wi, const Vec3& wo) const {
  if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
  const Vec3 h = (wi + wo).normalized();
  return p_.p.eval(wi) * p_.q.eval(h) * p_.p.eval(wo);
}

bool McCoolForm::isotropic() const {
  return p_.p.rotation_invariant() && p_.q.rotation_invariant();
}

std::string McCoolForm::to_string() const {
  return "mccool-form(" + eq_string('p', p_.p) + ", " + eq_string('q', p_.q) + ")";
}

void register_separable(Catalogue& cat) {
  {
    const SeparableParams def;
    std::vector<ParamInfo> params;
    add_eq_docs(params, 'a', def.a, "a(wi)");
    add_eq_docs(params, 'b', def.b, "b(wo)");
    add_eq_docs(params, 'c', def.c, "c(h)");
    cat.add_model(
        {"separable",
         "Synthetic planted-solution BRDF f = a(wi) b(wo) c(h), h = normalize(wi + wo); each "
         "factor g(w) = exp(g0 + g1 u + g2 v + g3 u^2 + g4 u v + g5 v^2), (u, v) = parabolic(w) "
         "= (w.x, w.y)/(1 + w.z), coefficients per channel. Reciprocal only when a = b.",
         params, [](const ParamDict& d) -> BrdfPtr {
           SeparableParams p;
           read_eq(d, 'a', p.a);
           read_eq(d, 'b', p.b);
           read_eq(d, 'c', p.c);
           return detail::make_checked<Separable>(d, p);
         }});
  }
  {
    const McCoolFormParams def;
    std::vector<ParamInfo> params;
    add_eq_docs(params, 'p', def.p, "p(wi), p(wo)");
    add_eq_docs(params, 'q', def.q, "q(h)");
    cat.add_model(
        {"mccool-form",
         "Synthetic BRDF of McCool et al. 2001's form f = p(wi) q(h) p(wo), p shared; factors "
         "g(w) = exp(g0 + g1 u + g2 v + g3 u^2 + g4 u v + g5 v^2) of the parabolic coordinates "
         "(u, v) of their direction, coefficients per channel. Reciprocal.",
         params, [](const ParamDict& d) -> BrdfPtr {
           McCoolFormParams p;
           read_eq(d, 'p', p.p);
           read_eq(d, 'q', p.q);
           return detail::make_checked<McCoolForm>(d, p);
         }});
  }
}

}  // namespace bf
