// Factorization objects in Python: evaluation (inherited from Brdf), metrics,
// texture arrays, exports (EXR/PNG/JSON/GLSL, model-fit JSON, MERL) and reload.
#include "brdfs/merl.h"
#include "common.h"
#include "factor/export.h"
#include "factor/model_fit.h"

namespace bf::py_module {

namespace {

py::dict exported_dict(const ExportedFiles& e) {
  py::dict d;
  d["sidecar"] = e.sidecar;
  d["glsl"] = e.glsl;
  d["textures"] = e.textures;
  d["previews"] = e.previews;
  d["data"] = e.data.empty() ? py::object(py::none()) : py::object(py::str(e.data));
  return d;
}

}  // namespace

std::shared_ptr<PyFactorization> wrap(FactorizationPtr f) {
  auto p = std::make_shared<PyFactorization>();
  p->brdf = f;
  p->f = std::move(f);
  return p;
}

namespace {

// metrics (docs/design.md §4) of `approx` on `s` as a dict, computed without
// the GIL.
py::dict score_dict(const Brdf& approx, const SampleSet& s, double eps) {
  eps = checked_metric_eps("score", eps);
  Metrics mt;
  {
    py::gil_scoped_release release;
    mt = evaluate_metrics(approx, s, LogTransform::of(s, eps));
  }
  return metrics_dict(mt);
}

// The module functions score() and load().
void bind_score_and_load(py::module_& m) {
  m.def(
      "score",
      [](const PyBrdf& approx, const SampleSet& s, double eps) { return score_dict(*approx.brdf, s, eps); },
      py::arg("approx"), py::arg("samples"), py::arg("metric_eps") = 1e-5,
      "Metrics (docs/design.md §4) of any BRDF (a factorization, a model, a reloaded export) on a sample set.");
  m.def(
      "load",
      [](const std::string& path) -> py::object {
        // The CLI's `--brdf FILE.json` reader: the file checked as a regular
        // file of bounded size (a FIFO or folder is refused at once, naming
        // it), read without the GIL.
        BrdfPtr b;
        {
          py::gil_scoped_release release;
          b = load_export(path);
        }
        if (auto f = std::dynamic_pointer_cast<const Factorization>(b)) return py::cast(wrap(f));
        auto p = std::make_shared<PyBrdf>();
        p->brdf = b;
        return py::cast(p);
      },
      py::arg("path"),
      R"doc(Reads an export back: a factorization sidecar (STEM.json of mccool, fit,
search, svd, sh-k, sh-r) as a Factorization (metrics None), a model-fit JSON
as a Brdf.)doc");
}

}  // namespace

void bind_factorization(py::module_& m) {
  py::class_<PyFactorization, PyBrdf, std::shared_ptr<PyFactorization>>(m, "Factorization", R"doc(
What a method returns: an approximation that evaluates like any Brdf
(eval/__call__ on (N, 3) arrays), with the method's report (metrics on the
fitted samples, errors after each term, time, evaluations), its description,
and exports.)doc")
      .def_property_readonly("method", [](const PyFactorization& f) { return f.f->method(); },
                             "\"mccool\", \"fit\", \"search\", \"svd\", \"sh-k\", \"sh-r\", \"model-fit\" (+\"+refine-<objective>\")")
      .def_property_readonly("storage_floats", [](const PyFactorization& f) { return f.f->storage_floats(); },
                             "floats a renderer must store")
      .def_property_readonly(
          "metrics", [](const PyFactorization& f) -> py::object { return f.metrics ? py::object(metrics_dict(*f.metrics)) : py::none(); },
          "dict rel_mse, rel_mae, rel_max, lin_rmse, lin_mae, lin_max, cos_rmse, samples on the samples it was fitted "
          "to (scored with metric_eps), or None (tabulating method without samples, reloaded export)")
      .def_readonly("metric_eps", &PyFactorization::metric_eps)
      .def_readonly("errors_after_term", &PyFactorization::errors_after_term,
                    "homomorphic methods: rel_mse on the fit data after each term (a structured search: element "
                    "k is its own k-term answer's error, not a prefix of this factorization)")
      .def_readonly("seconds", &PyFactorization::seconds, "wall time of the method")
      .def_readonly("evaluations", &PyFactorization::evaluations, "search: inner-loop fits; model-fit: LM iterations")
      .def_property_readonly("info", [](const PyFactorization& f) { return to_python(f.info); },
                             "method-specific record (search terms, refinement report, model-fit parameters, ...)")
      .def("describe", [](const PyFactorization& f) { return to_python(f.f->describe()); },
           "Everything needed to rebuild it, as in the export sidecar (dict).")
      .def(
          "score",
          [](const PyFactorization& f, const SampleSet& s, double eps) { return score_dict(*f.f, s, eps); },
          py::arg("samples"), py::arg("metric_eps") = 1e-5,
          "Metrics (docs/design.md §4) of this approximation on any sample set.")
      .def(
          "textures",
          [](const PyFactorization& f) {
            // What the exported GLSL samples (Factorization::viewer_data): the
            // result says, no branch on its type here.
            std::optional<ShaderView> v;
            {
              py::gil_scoped_release release;
              v = f.f->viewer_data();
            }
            if (!v || v->textures.empty())
              throw std::invalid_argument("textures: method " + f.f->method() +
                                          " stores no textures (its export samples none)");
            py::list out;
            for (const auto& [name, img] : v->textures) {
              const int w = img.width, h = img.height, nc = img.channels();
              py::array_t<float> a({h, w, nc});
              std::copy(img.pixels.begin(), img.pixels.end(), a.mutable_data());
              out.append(a);
            }
            return out;
          },
          "The textures the exported GLSL samples, in binding order, each a (height, width, channels) float32 "
          "array, [j, i] = texel (i, j), what the export's EXR holds. mccool, fit, search: each term's log-space "
          "texels (res, res, 3), 0 outside the mask; svd, sh-k: their factor tables. Raises ValueError for a "
          "result that stores none (sh-r, model-fit).")
      .def_property_readonly("A", [](const PyFactorization& f) -> py::object {
        // The sidecar's per-channel scale (describe()["A"]) where the result has one.
        const nlohmann::json d = f.f->describe();
        const auto a = d.find("A");
        if (a == d.end() || !a->is_array() || a->size() != 3) return py::none();
        return py::make_tuple((*a)[0].get<double>(), (*a)[1].get<double>(), (*a)[2].get<double>());
      }, "mccool, fit, search: the per-channel scale A of the sidecar, else None")
      .def(
          "export",
          [](const PyFactorization& f, const std::string& dir, const std::string& stem) -> py::dict {
            ExportedFiles e;
            {
              py::gil_scoped_release release;
              e = write_export(*f.f, dir, stem);  // what a run writes with experiment.export on
            }
            return exported_dict(e);
          },
          py::arg("dir"), py::arg("stem") = "factors",
          R"doc(Writes the export into dir, as a run does with experiment.export on:
mccool, fit, search: STEM_termK.exr/.png, STEM.json (sidecar), STEM.glsl;
svd, sh-k, sh-r: STEM.f64 (every number the evaluation reads), STEM_*.exr
(svd, sh-k), STEM.glsl, STEM.json; model-fit: STEM.json, STEM.glsl. Returns
the paths (dict: sidecar, glsl, textures, previews, data). load(sidecar)
reads any of them back (bit-identical evaluation).)doc")
      .def(
          "export_merl",
          [](const PyFactorization& f, const std::string& path) {
            py::gil_scoped_release release;
            MerlTabulateStats st;
            write_merl(merl_tabulate(*f.f, &st), path);
          },
          py::arg("path"), "Tabulates it as a MERL .binary table (90x90x180, float64 RGB), as `brdf-factor export-merl`.")
      .def("__repr__", [](const PyFactorization& f) {
        std::string r = "<brdf_factor.Factorization " + f.f->method() + ", " + std::to_string(f.f->storage_floats()) +
                        " floats";
        if (f.metrics) r += ", rel_mse " + std::to_string(f.metrics->rel_mse);
        return r + ">";
      });

  bind_score_and_load(m);
}

}  // namespace bf::py_module
