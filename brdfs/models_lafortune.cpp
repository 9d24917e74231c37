// Lafortune generalized cosine lobes: any number of per-channel lobes plus a
// Lambertian term, unnormalized (paper, pbrt-v1) or Ngan-normalized.
#include <cmath>
#include <map>

#include "brdfs/catalogue.h"
#include "brdfs/models.h"
#include "brdfs/models_internal.h"

namespace bf {

namespace {
const std::vector<std::string> kNormalizations = {"none", "ngan"};
const char* kModel = "lafortune";

// max(|cx|, |cy|, |cz|) per channel.
Rgb max_abs_c(const LafortuneLobe& l) {
  return l.cx.abs().max(l.cy.abs()).max(l.cz.abs());
}

// Splits "cxy12" into ("cxy", 12); returns false unless key is one of the lobe
// prefixes followed by a canonical decimal index.
bool split_lobe_key(const std::string& key, std::string& prefix, int& index) {
  const auto pos = key.find_first_of("0123456789");
  if (pos == std::string::npos || pos == 0) return false;
  prefix = key.substr(0, pos);
  if (prefix != "cx" && prefix != "cy" && prefix != "cxy" && prefix != "cz" && prefix != "n" &&
      prefix != "ks")
    return false;
  const std::string digits = key.substr(pos);
  if (digits.find_first_not_of("0123456789") != std::string::npos) return false;
  if (digits.size() > 1 && digits[0] == '0') return false;  // "n01" is not lobe 1
  if (digits.size() > 6) {
    index = 1000000;
    return true;
  }
  index = std::stoi(digits);
  return true;
}
}  // namespace

void LafortuneParams::validate() const {
  detail::require_nonneg(kModel, "rho_d", rho_d);
  detail::require(lobes.size() <= static_cast<size_t>(kMaxLobes), kModel, "number of lobes",
                  std::to_string(lobes.size()), "<= " + std::to_string(kMaxLobes));
  for (size_t k = 0; k < lobes.size(); ++k) {
    const LafortuneLobe& l = lobes[k];
    const std::string s = std::to_string(k);
    for (const auto& [key, v] : {std::pair{"cx", &l.cx}, {"cy", &l.cy}, {"cz", &l.cz}})
      detail::require(v->isFinite().all(), kModel, key + s, detail::fmt(*v), "finite");
    detail::require_nonneg(kModel, "n" + s, l.n);
    detail::require_nonneg(kModel, "ks" + s, l.ks);
    // v <= max|C| for unit wi, wo (Cauchy-Schwarz), so this bounds the lobe.
    const Rgb c = max_abs_c(l);
    for (int ch = 0; ch < 3; ++ch)
      detail::require(c[ch] <= 1.0 || l.n[ch] * std::log(c[ch]) <= std::log(1e300), kModel, "n" + s,
                      detail::fmt(l.n),
                      "small enough that max(|cx" + s + "|, |cy" + s + "|, |cz" + s + "|)^n" + s +
                          " <= 1e300 in every channel (the lobe would overflow)");
  }
}

Lafortune::Lafortune(const LafortuneParams& p) : p_(p) {
  p_.validate();
  for (const LafortuneLobe& l : p_.lobes) {
    Rgb s = l.ks, inv_c = Rgb::Ones();
    if (p_.normalization == LafortuneParams::Normalization::Ngan) {
      // (n + 2) / (2 pi) pow+(v / max|C|, n): the same as dividing by
      // max(C^2)^(n/2), without its underflow for large n (0.58^1630 < 1e-308).
      // A zero C vector gives a zero lobe.
      const Rgb c = max_abs_c(l);
      for (int ch = 0; ch < 3; ++ch) {
        s[ch] = c[ch] > 0.0 ? l.ks[ch] * (l.n[ch] + 2.0) / (2.0 * M_PI) : 0.0;
        inv_c[ch] = c[ch] > 0.0 ? 1.0 / c[ch] : 0.0;
      }
    }
    scale_.push_back(s);
    inv_c_.push_back(inv_c);
  }
}

Rgb Lafortune::eval(const Vec3& wi, const Vec3& wo) const {
  if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
  const double xx = wi.x() * wo.x(), yy = wi.y() * wo.y(), zz = wi.z() * wo.z();
  Rgb f = p_.rho_d / M_PI;
  for (size_t k = 0; k < p_.lobes.size(); ++k) {
    const LafortuneLobe& l = p_.lobes[k];
    const Rgb v = (l.cx * xx + l.cy * yy + l.cz * zz) * inv_c_[k];
    for (int c = 0; c < 3; ++c)
      if (v[c] > 0.0 && scale_[k][c] != 0.0) f[c] += scale_[k][c] * std::pow(v[c], l.n[c]);
  }
  return f;
}

bool Lafortune::isotropic() const {
  for (const LafortuneLobe& l : p_.lobes)
    if ((l.cx != l.cy).any()) return false;
  return true;
}

std::string Lafortune::to_string() const {
  std::string s = "lafortune(rho_d=" + detail::fmt(p_.rho_d);
  for (size_t k = 0; k < p_.lobes.size(); ++k) {
    const LafortuneLobe& l = p_.lobes[k];
    const std::string i = std::to_string(k);
    if ((l.cx == l.cy).all())
      s += ", cxy" + i + "=" + detail::fmt(l.cx);
    else
      s += ", cx" + i + "=" + detail::fmt(l.cx) + ", cy" + i + "=" + detail::fmt(l.cy);
    s += ", cz" + i + "=" + detail::fmt(l.cz) + ", n" + i + "=" + detail::fmt(l.n);
    if ((l.ks != 1.0).any()) s += ", ks" + i + "=" + detail::fmt(l.ks);
  }
  return s + ", normalization=" + kNormalizations[static_cast<int>(p_.normalization)] + ")";
}

namespace {
// Reads the lobes from keys cxy<k> | cx<k> + cy<k>, cz<k>, n<k>, ks<k>.
std::vector<LafortuneLobe> read_lobes(const ParamDict& d) {
  const std::string where = d.origin() + ": lafortune: ";
  std::map<int, std::map<std::string, bool>> seen;  // lobe -> prefixes present
  for (const std::string& key : d.keys()) {
    std::string prefix;
    int index = 0;
    if (!split_lobe_key(key, prefix, index)) continue;  // unknown keys are reported later
    if (index >= LafortuneParams::kMaxLobes)
      throw std::invalid_argument(where + "lobe index in '" + key + "' must be < " +
                                  std::to_string(LafortuneParams::kMaxLobes));
    seen[index][prefix] = true;
  }
  if (seen.empty()) return LafortuneParams{}.lobes;  // the default lobe
  const int count = seen.rbegin()->first + 1;
  std::vector<LafortuneLobe> lobes(count);
  for (int k = 0; k < count; ++k) {
    const std::string s = std::to_string(k);
    auto& has = seen[k];
    const std::string rule =
        " (each lobe k = 0, 1, ... takes cz<k>, n<k>, either cxy<k> or both cx<k> and cy<k>, "
        "and optionally ks<k>)";
    if (!has["cz"]) throw std::invalid_argument(where + "lobe " + s + " needs cz" + s + rule);
    if (!has["n"]) throw std::invalid_argument(where + "lobe " + s + " needs n" + s + rule);
    if (has["cxy"] && (has["cx"] || has["cy"]))
      throw std::invalid_argument(where + "cxy" + s + " and cx" + s + "/cy" + s +
                                  " were given together; give either cxy" + s +
                                  " (cx = cy) or both cx" + s + " and cy" + s);
    if (!has["cxy"] && !(has["cx"] && has["cy"]))
      throw std::invalid_argument(where + "lobe " + s + " needs cxy" + s + " or both cx" + s +
                                  " and cy" + s + rule);
    LafortuneLobe& l = lobes[k];
    if (has["cxy"]) {
      l.cx = l.cy = d.get_rgb("cxy" + s, l.cx);
    } else {
      l.cx = d.get_rgb("cx" + s, l.cx);
      l.cy = d.get_rgb("cy" + s, l.cy);
    }
    l.cz = d.get_rgb("cz" + s, l.cz);
    l.n = d.get_rgb("n" + s, l.n);
    l.ks = d.get_rgb("ks" + s, l.ks);
  }
  return lobes;
}
}  // namespace

void register_lafortune(Catalogue& cat) {
  const LafortuneParams def;
  const LafortuneLobe& l0 = def.lobes.front();
  cat.add_model(
      {"lafortune",
       "f = rho_d/pi + sum_k ks<k> N_k pow+(cx<k> wi.x wo.x + cy<k> wi.y wo.y + cz<k> wi.z wo.z, "
       "n<k>), pow+(v,e) = v > 0 ? v^e : 0, every coefficient per channel (r/g/b or one number). "
       "Lobes k = 0, 1, ... (contiguous, at most 64) each need cz<k>, n<k> and cxy<k> (sets "
       "cx = cy) or both cx<k> and cy<k>; with no lobe keys at all the default lobe 0 below is "
       "used. N_k = 1 (normalization=none: the paper and pbrt-v1) or (n+2)/(2 pi max(C^2)^(n/2)) "
       "(normalization=ngan: Ngan et al. 2005). Source: Lafortune et al. 1997.",
       {{"rho_d", detail::fmt(def.rho_d), "diffuse albedo, >= 0"},
        {"cxy<k>", detail::fmt(l0.cx), "lobe k: cx = cy (default lobe 0 only)"},
        {"cx<k>", detail::fmt(l0.cx), "lobe k: x coefficient, with cy<k>, instead of cxy<k>"},
        {"cy<k>", detail::fmt(l0.cy), "lobe k: y coefficient, with cx<k>"},
        {"cz<k>", detail::fmt(l0.cz), "lobe k: z coefficient"},
        {"n<k>", detail::fmt(l0.n), "lobe k: exponent, >= 0"},
        {"ks<k>", detail::fmt(l0.ks), "lobe k: scale, >= 0 (optional)"},
        {"normalization", "none", "none | ngan (see above)"}},
       [](const ParamDict& d) -> BrdfPtr {
         LafortuneParams p;
         p.rho_d = d.get_rgb("rho_d", p.rho_d);
         p.lobes = read_lobes(d);
         p.normalization = static_cast<LafortuneParams::Normalization>(
             detail::parse_choice(d, kModel, "normalization", 0, kNormalizations));
         return detail::make_checked<Lafortune>(d, p);
       }});
}

}  // namespace bf
