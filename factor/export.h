// Factor export (docs/design.md §5): a HomomorphicFactorization written as float
// EXR textures, PNG previews, a JSON sidecar and a generated GLSL function, and
// read back from the sidecar so that the reloaded factorization evaluates
// bit-identically to the one that was written.
//
// Files, for stem STEM in folder DIR (all written atomically: each to a hidden
// temporary in DIR, renamed into place once every file is complete, the
// sidecar last, so an interrupted export leaves either the old files or the
// new ones, never a half file):
//   STEM_termK.exr   term K's log-space texels, float32, channels R, G, B,
//                    res x res; pixel (x, y) = texel (i, j) = (x, y), index
//                    j*res + i; scanline y = 0 comes first. Texels outside the
//                    projection mask are 0.
//   STEM_termK.png   preview: the factor value v = mean over R, G, B of exp
//                    of the log texels, as log10 v on a fixed range
//                    [kPreviewLog10Min, kPreviewLog10Max] (the same for every
//                    term: not normalized per term; clamped at the ends) in
//                    the heat colour map black - blue (0.1, 0.15, 0.85) - red
//                    (0.9, 0.1, 0.2) - yellow (1, 0.85, 0.1) - white at 0,
//                    1/4, 1/2, 3/4, 1, 8 bit; each texel a block of
//                    max(1, 256/res) pixels; texels outside the mask are
//                    flat grey (128, 128, 128), a colour not on the map.
//   STEM.glsl        vec3 brdf_factor_eval(vec3 wi, vec3 wo), see factor/glsl.h.
//   STEM.json        the sidecar: HomomorphicFactorization::describe() plus
//                    format, format_version, texture file names and the
//                    texel-coordinate mapping per term (see write_factorization).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "factor/homomorphic.h"

namespace bf {

class Catalogue;

// Version of the sidecar layout written by write_factorization and the only one
// load_factorization accepts. Bump when a field changes meaning.
inline constexpr int kFactorExportFormatVersion = 1;
// The range of log10 (factor value) that the PNG previews' colour map spans.
inline constexpr double kPreviewLog10Min = -3.0;
inline constexpr double kPreviewLog10Max = 3.0;
// Value of the sidecar's "format" field.
inline constexpr const char* kFactorExportFormat = "brdf-factor-factorization";

// ExportedFiles (the paths one export wrote): factor/factorization.h.


// Writes the export of `f` into `dir` (created if missing) with file names
// starting with `stem` (non-empty, no '/'). Throws std::invalid_argument if the
// factorization holds non-finite values (texels, matrix entries), naming term,
// texel and channel; std::runtime_error naming the path if a file cannot be
// written. On any error, no temporary is left behind and no final file has
// been replaced.
//
// Sidecar fields (besides those of describe()):
//   format ("brdf-factor-factorization"), format_version (1), glsl (file name),
//   combine (how terms combine, in words), texture_layout, conventions;
//   per term: texture, preview, sampler (GLSL uniform name), channels,
//   texel_matrix (2x4) and texel_offset (2) with
//     s = clamp(texel_matrix * x + texel_offset, 0, resolution - 1),
//     texel_matrix row r = matrix row r * row_scale_r * (resolution - 1) / 2,
//   uv ((s + 0.5) / resolution, the GL_LINEAR coordinate), and for reciprocal
//   terms conjugate_matrix and conjugate_texel_matrix.
ExportedFiles write_factorization(const HomomorphicFactorization& f, const std::string& dir,
                                  const std::string& stem);

// Reads an export back from its sidecar (texture paths relative to the
// sidecar's folder). Validates the format and version, every field's presence,
// type and range (matrix 2x4, finite, no zero row; resolution 2..1024; A finite
// and > 0; eps in (0, 1]; quaternion_pair 8 finite numbers if present), and
// each EXR (size equal to the resolution, 3 channels, finite texels, zero
// outside the projection mask, mask size equal to mask_texels if given).
// Texture names must stay inside the sidecar's folder (relative, no '..');
// at most kMaxSidecarTerms terms and kMaxSidecarTexels texels over all terms;
// the sidecar and each texture must be regular files (brdfs/file_check.h).
// Throws std::invalid_argument with a message naming the file, the field, what
// was expected and what was found.
inline constexpr size_t kMaxSidecarTerms = 1024;
inline constexpr uint64_t kMaxSidecarTexels = uint64_t(1) << 26;  // 64 terms of 1024x1024
std::shared_ptr<HomomorphicFactorization> load_factorization(const std::string& json_path);

// The export of any factorization that has one, as a run writes it with
// experiment.export on and Factorization.export() in Python: checks the stem
// (non-empty, no '/'), then f.write_export_files (factor/factorization.h):
// homomorphic (mccool, fit, search, refined or not) by write_factorization;
// svd, sh-k, sh-r by write_baseline_export (factor/baseline_export.h);
// model-fit as STEM.json (write_model_fit) and STEM.glsl (generate_model_glsl,
// `origin` in its header comment).
// Throws std::invalid_argument naming the method when it has no export.
ExportedFiles write_export(const Factorization& f, const std::string& dir, const std::string& stem,
                           const std::string& origin = "");

// Reads back what write_export wrote, from the sidecar STEM.json (dispatching
// as the ".json" loader below does): a model fit's catalogue BRDF, or the
// factorization. The file is checked as every reader's (brdfs/file_check.h).
BrdfPtr load_export(const std::string& json_path);

// Reads back the export of a result type outside those formats: load_export
// (and so the ".json" loader, `--brdf STEM.json`, Python's bf.load) calls
// `read` for a sidecar whose "method" is `method`, before the built-in
// formats. An empty `read` removes the reader (tests).
using ExportReader = std::function<std::shared_ptr<const Factorization>(const std::string& json_path)>;
void register_export_reader(const std::string& method, ExportReader read);

// Registers the ".json" loader, so a sidecar path works wherever a BRDF spec is
// accepted (`--brdf results/run/factors.json`). It takes no options.
void register_export_loader(Catalogue& cat);

}  // namespace bf
