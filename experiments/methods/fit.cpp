// kind = "fit": the homomorphic fit for explicitly given projections; with a
// tolerance, the first prefix of them (and with texture_size = "auto" the
// resolution) reaching an error target.
#include <cmath>

#include "experiments/methods/homomorphic.h"
#include "factor/size_select.h"

namespace bf {

using nlohmann::json;

namespace {

const std::vector<std::string>& projection_keys() {
  static const std::vector<std::string> keys = {"parameterization", "matrix", "name", "reciprocal"};
  return keys;
}

void read_projections(Reader& r, MethodVariant& m, json& o) {
  Ctx& ctx = r.ctx();
  const toml::node* n = r.take("projections");
  if (!n) {
    r.fail_table("kind = \"fit\" needs projections = [{ name = \"wi\" }, { matrix = [[...], [...]] }, ...]");
    return;
  }
  auto a = n->as_array();
  if (!a || a->empty()) {
    r.fail("projections", "expected a non-empty list of tables "
                          "{ parameterization, matrix = [[4 numbers], [4 numbers]] or name, reciprocal }, " +
                              found(*n));
    return;
  }
  json list = json::array();
  for (size_t j = 0; j < a->size(); ++j) {
    const toml::node& e = *a->get(j);
    const std::string field = r.field("projections[" + std::to_string(j) + "]");
    auto t = e.as_table();
    if (!t) {
      ctx.issue(ctx.where(e), field, "expected a table { parameterization, matrix or name, reciprocal }, " + found(e));
      r.mark_failed();
      continue;
    }
    const Combo c = plain_combo(*t);
    Reader pr(ctx, c, field, ctx.where(e));
    const bool has_param = pr.has("parameterization");
    Parameterization param = read_param(pr, "parameterization", homomorphic_options(m).param);
    const bool recip = pr.boolean("reciprocal", homomorphic_options(m).reciprocity);
    Mat24 P = Mat24::Zero();
    std::string name;
    if (pr.has("matrix") == pr.has("name")) {
      if (pr.has("matrix")) {
        pr.fail("name", "matrix and name are alternatives: give one of them, found both");
        pr.take("matrix");  // reported above: not unknown keys besides
        pr.take("name");
      } else {
        pr.fail_table("expected matrix = [[4 numbers], [4 numbers]] or name = \"wi\" | \"wo\" | \"h\" | \"d\"");
      }
    } else if (pr.has("name")) {
      name = pr.choice("name", "wi", {"wi", "wo", "h", "d"});
      const Parameterization implied = (name == "wi" || name == "wo") ? Parameterization::WiWo
                                                                       : Parameterization::HalfDiff;
      if (has_param && param != implied)
        pr.fail("name", "name = \"" + name + "\" is a " + to_string(implied) +
                            " projection, but parameterization = \"" + to_string(param) + "\"");
      param = implied;
      const bool first = name == "wi" || name == "h";
      P = first ? projection_first_pair(param, m.texture_size).P : projection_second_pair(param, m.texture_size).P;
    } else {
      const toml::node* mn = pr.take("matrix");
      auto rows = mn->as_array();
      bool ok = rows && rows->size() == 2;
      for (size_t rr = 0; ok && rr < 2; ++rr) {
        auto row = rows->get(rr)->as_array();
        ok = row && row->size() == 4;
        for (size_t cc = 0; ok && cc < 4; ++cc) {
          const auto v = row->get(cc)->value<double>();
          ok = v.has_value() && std::isfinite(*v);
          if (ok) P(rr, cc) = *v;
        }
      }
      if (!ok) pr.fail("matrix", "expected [[4 numbers], [4 numbers]] (a 2x4 matrix), " + found(*mn));
    }
    pr.finish(projection_keys(), "a projection");
    if (pr.failed()) {
      r.mark_failed();
      continue;
    }
    Projection proj{param, P, m.texture_size};
    try {
      proj.validate();
    } catch (const std::exception& ex) {
      ctx.issue(pr.where(name.empty() ? "matrix" : "name"), field + (name.empty() ? ".matrix" : ".name"),
                std::string(ex.what()) + " (rows must be orthonormal)");
      r.mark_failed();
      continue;
    }
    homomorphic_options(m).projections.push_back({proj, recip, std::nullopt});
    json pj = {{"parameterization", to_string(param)}, {"reciprocal", recip}};
    if (!name.empty()) pj["name"] = name;
    pj["matrix"] = {{P(0, 0), P(0, 1), P(0, 2), P(0, 3)}, {P(1, 0), P(1, 1), P(1, 2), P(1, 3)}};
    list.push_back(pj);
  }
  o["projections"] = list;
}

const std::vector<KeySpec>& fit_kind_keys() {
  static const std::vector<KeySpec> keys = [] {
    std::vector<KeySpec> k = fit_keys(homomorphic_texture_key());
    const auto r = refine_keys();
    k.insert(k.end(), r.begin(), r.end());
    const std::vector<KeySpec> own = {
        other_key("projections", "list of tables", "required",
                  "the terms, in order; each `{ parameterization, matrix \\| name, reciprocal }`"),
        int_key("terms", 1, 1024, "all projections", "use the first `terms` projections; with a tolerance, the cap"),
        choice_key("parameterization", {"wiwo", "halfdiff"}, "wiwo", "default of the projections' `parameterization`"),
        bool_key("reciprocity", "false", "default of the projections' `reciprocal`"),
        other_key("tolerance", "table", "",
                  "stop at the first prefix of the projections whose error reaches the target; with "
                  "`texture_size = \"auto\"` also the resolution"),
        other_key("texture_ladder", "list of integers", "[8, 12, 16, 24, 32]",
                  "the resolutions `texture_size = \"auto\"` tries, ascending")};
    k.insert(k.end(), own.begin(), own.end());
    return k;
  }();
  return keys;
}

class FitKind final : public HomomorphicKind {
 public:
  std::string name() const override { return "fit"; }
  std::string summary() const override {
    return "The homomorphic fit for explicitly given projections. A projection table: `parameterization` "
           "(`\"wiwo\"` | `\"halfdiff\"`, the 4D point the matrix acts on), `matrix` ([[4 numbers], [4 numbers]], "
           "a 2×4 projection with orthonormal rows) or `name` (`\"wi\"` | `\"wo\"` | `\"h\"` | `\"d\"`: the first / "
           "second coordinate pair of wiwo or halfdiff), `reciprocal` (bool: read the texture through the "
           "conjugate projection too).";
  }
  std::vector<KeySpec> keys() const override { return fit_kind_keys(); }
  std::string example() const override {
    return "projections = [{ name = \"wi\" }, { name = \"h\" }]\ntexture_size = 6\n";
  }
  std::vector<std::string> described() const override {
    return {"terms", "texture_size", "parameterization", "reciprocity"};
  }
  bool array_is_value(const std::string& key, const toml::array& a) const override {
    return (key == "projections" || key == "texture_ladder") && !all_arrays(a);
  }

  void read(Reader& r, MethodVariant& m, json& o, uint64_t) const override {
    read_refine_options(r, m, o);
    // texture_size = "cv": the ladder's middle until the choice (finish_refine_options).
    m.texture_size = take_texture_cv(r, o, true) ? 16 : read_texture_size(r, m, o, 16, kFitTextureMin, kFitTextureMax);
    HomomorphicOptions& h = homomorphic_options(m);
    h.param = read_param(r, "parameterization", Parameterization::WiWo);
    h.reciprocity = r.boolean("reciprocity", false);
    read_fit_options(r, h.fit, o);
    m.tolerance = read_tolerance(r, o);
    o["parameterization"] = to_string(h.param);
    o["reciprocity"] = h.reciprocity;
    read_projections(r, m, o);
    const int n = static_cast<int>(h.projections.size());
    m.terms = static_cast<int>(r.integer(find_key(fit_kind_keys(), "terms"), std::max(n, 1)));
    if (n > 0 && m.terms > n)
      r.fail("terms", "terms = " + std::to_string(m.terms) + " but only " + std::to_string(n) +
                          " projections are given (terms uses the first `terms` of them)");
    o["terms"] = m.terms;
    if (m.tolerance) {
      m.cap = r.has("terms") ? m.terms : n;
      o["max_terms"] = m.cap;
    }
    validate_fit_options(r, m);
    finish_refine_options(r, m, o);
  }

  MethodOutcome run(const RunContext& c) const override {
    const MethodVariant& m = c.method;
    const HomomorphicOptions& h = homomorphic_options(m);
    const FitData data(c.samples, h.fit.eps);
    HomomorphicRun run;
    std::optional<SizeChoice> choice;
    if (m.tolerance) {
      const std::vector<int> ladder =
          m.texture_ladder.empty() ? std::vector<int>{m.texture_size} : m.texture_ladder;
      const auto terms_at = [&](int res) { return terms_at_resolution(h.projections, res); };
      choice = select_homomorphic_size(data, c.samples, c.lt, terms_at, 1, m.cap, h.fit, "fit", *m.tolerance, ladder);
      run.h = std::dynamic_pointer_cast<const HomomorphicFactorization>(choice->result);
      run.errors_after_term = choice->errors_after_term;
    } else {
      run.h = fit_homomorphic(data, std::vector<TermSpec>(h.projections.begin(), h.projections.begin() + m.terms),
                              h.fit, "fit", &run.errors_after_term);
    }
    return finish_homomorphic(c, std::move(run), std::move(choice), 0);
  }
};

}  // namespace

std::shared_ptr<const MethodKind> make_fit_kind() { return std::make_shared<FitKind>(); }

}  // namespace bf
