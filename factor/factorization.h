// Factorization: what every method (homomorphic fit, McCool, search, SVD, SH,
// model fit) returns. It is itself a Brdf (so metrics, renders and MERL export
// treat an approximation like any other BRDF), knows how many floats a
// renderer must store, describes itself as JSON for the export sidecar, and
// owns its outputs: the export files, the GLSL that evaluates it, and the data
// report.html's viewer draws it with. Runs, the viewer, the exporters and
// Python reach these through the virtual members below and never ask which
// concrete type a result is; a new result type overrides them in its own file.
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "brdfs/brdf.h"
#include "factor/image_io.h"

namespace bf {

// Paths of the files one export wrote (absolute or as given by dir).
struct ExportedFiles {
  std::string sidecar;                // DIR/STEM.json
  std::string glsl;                   // DIR/STEM.glsl
  std::vector<std::string> textures;  // DIR/STEM_*.exr (homomorphic: one per term; svd, sh-k: theirs)
  std::vector<std::string> previews;  // DIR/STEM_termK.png (homomorphic: one per term)
  std::string data;                   // DIR/STEM.f64 (svd, sh-k, sh-r; empty otherwise)
};

// What the viewer (experiments/report/viewer.h) draws an approximation with:
// its GLSL (vec3 brdf_factor_eval(vec3 wi, vec3 wo), the formula the export's
// STEM.glsl holds) and the float32 RGB textures that GLSL samples, each with
// its sampler name, in binding order.
struct ShaderView {
  std::string glsl;
  std::vector<std::pair<std::string, FloatImage>> textures;
};

class Factorization : public Brdf {
 public:
  // Method name as written in results.csv ("fit", "mccool", "search", "svd", "sh-k", ...).
  virtual std::string method() const = 0;
  // Floats a renderer must hold: texels x channels + per-term constants.
  virtual size_t storage_floats() const = 0;
  // Everything needed to rebuild and evaluate this approximation (without the
  // texel arrays, which the exporter writes as images). See factor/export.h.
  virtual nlohmann::json describe() const = 0;

  // ---- Outputs. The defaults say "none"; a result type that has an output
  // overrides its member (see docs/design.md "How a method kind plugs in").

  // Writes the export into `dir` (created if missing), file names starting
  // with `stem` (non-empty, no '/': an override throws std::invalid_argument
  // otherwise); `origin` (e.g. "run <id>") may go into comments. Files are
  // written atomically (factor/atomic_batch.h). Called by write_export()
  // (factor/export.h).
  // Default: throws std::invalid_argument naming the method.
  virtual ExportedFiles write_export_files(const std::string& dir, const std::string& stem,
                                           const std::string& origin) const;
  // The GLSL of the export (STEM.glsl): vec3 brdf_factor_eval(vec3 wi, vec3 wo),
  // one text that compiles for every target of factor/glsl_target.h (OpenGL
  // 3.3 core / 4.5, OpenGL ES 3.0, Vulkan). Texture file names derived from
  // `stem` may appear in comments, `origin` in the header comment.
  // Default: throws std::invalid_argument naming the method.
  virtual std::string glsl(const std::string& stem, const std::string& origin) const;
  // What report.html's viewer draws it with, or nullopt when it has no viewer
  // (the default). A kind whose results have one says so by
  // MethodKind::has_viewer() (experiments/methods/method_kind.h); the runner
  // refuses a result that contradicts it.
  virtual std::optional<ShaderView> viewer_data() const { return std::nullopt; }
  // Sampling data (importance sampling of the approximation) is not a member:
  // factor/sampling.h builds a sampler from any Brdf (make_sampler). A result
  // type that can sample its own factors exactly adds its override there, as a
  // virtual here with a default of "use the generic sampler".
};

using FactorizationPtr = std::shared_ptr<const Factorization>;

}  // namespace bf
