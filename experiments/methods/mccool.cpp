// kind = "mccool": McCool's fixed projections, p(wi) and p(wo) reading one
// reciprocal texture (wiwo) and p(h) another (halfdiff); with a tolerance and
// texture_size = "auto", the resolution chosen from a ladder.
#include "experiments/methods/homomorphic.h"
#include "factor/size_select.h"

namespace bf {

namespace {

class McCoolKind final : public HomomorphicKind {
 public:
  std::string name() const override { return "mccool"; }
  std::string summary() const override {
    return "McCool's fixed projections: p(wi) and p(wo) read one reciprocal texture (wiwo), p(h) another "
           "(halfdiff). With `texture_size = \"auto\"` a `tolerance` picks the resolution. The "
           "`parameterization` column says `wiwo+halfdiff`.";
  }
  std::vector<KeySpec> keys() const override {
    std::vector<KeySpec> k = fit_keys(homomorphic_texture_key());
    const auto r = refine_keys();
    k.insert(k.end(), r.begin(), r.end());
    k.push_back(other_key("terms", "integer", "2", "only 2: McCool's two textures"));
    k.push_back(other_key("tolerance", "table", "",
                          "with `texture_size = \"auto\"`: the smallest resolution reaching the target"));
    k.push_back(other_key("texture_ladder", "list of integers", "[8, 12, 16, 24, 32]",
                          "the resolutions `texture_size = \"auto\"` tries, ascending"));
    return k;
  }
  std::string example() const override { return "texture_size = 6\n"; }
  std::vector<std::string> described() const override { return {"texture_size"}; }

  void read(Reader& r, MethodVariant& m, nlohmann::json& o, uint64_t) const override {
    read_refine_options(r, m, o);
    // texture_size = "cv": the ladder's middle until the choice (finish_refine_options).
    m.texture_size = take_texture_cv(r, o, true) ? 16 : read_texture_size(r, m, o, 16, kFitTextureMin, kFitTextureMax);
    m.tolerance = read_tolerance(r, o);
    if (m.tolerance && m.texture_ladder.empty())
      r.fail("tolerance", "kind = \"mccool\" has exactly 2 textures: a tolerance can only choose the resolution "
                          "(set texture_size = \"auto\")");
    if (const toml::node* tn = r.take("terms"); tn && !(tn->is_integer() && tn->as_integer()->get() == 2))
      r.fail("terms", "kind = \"mccool\" has exactly 2 textures (p(wi)/p(wo) shared, and p(h)), found " +
                          show(*tn));
    m.terms = 2;
    HomomorphicOptions& h = homomorphic_options(m);
    read_fit_options(r, h.fit, o);
    h.param = Parameterization::WiWo;
    o["terms"] = 2;
    validate_fit_options(r, m);
    finish_refine_options(r, m, o);
  }

  MethodOutcome run(const RunContext& c) const override {
    const MethodVariant& m = c.method;
    const FitOptions& fit = homomorphic_options(m).fit;
    const FitData data(c.samples, fit.eps);
    HomomorphicRun run;
    std::optional<SizeChoice> choice;
    if (m.tolerance) {
      choice = select_homomorphic_size(data, c.samples, c.lt, mccool_terms, 2, 2, fit, "mccool", *m.tolerance,
                                       m.texture_ladder);
      run.h = std::dynamic_pointer_cast<const HomomorphicFactorization>(choice->result);
      run.errors_after_term = choice->errors_after_term;
    } else {
      run.h = fit_homomorphic(data, mccool_terms(m.texture_size), fit, "mccool", &run.errors_after_term);
    }
    return finish_homomorphic(c, std::move(run), std::move(choice), 0);
  }
};

}  // namespace

std::shared_ptr<const MethodKind> make_mccool_kind() { return std::make_shared<McCoolKind>(); }

}  // namespace bf
