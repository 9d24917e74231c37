// Export of the SVD, SH-K and SH-R baselines (docs/design.md §5.8): what a renderer
// needs to evaluate them, and what `--brdf STEM.json` reloads so that it
// evaluates exactly as the factorization that was written.
//
// Files, for stem STEM in folder DIR (written to hidden temporaries and
// renamed into place, the sidecar last):
//   STEM.f64     every number the evaluation reads, little-endian IEEE float64,
//                no header: the blocks listed in the sidecar's data.blocks
//                (name, offset in values, shape, index order). The reload
//                reads these, so it is exact.
//   STEM_*.exr   the same data as float32 RGB textures for the GLSL:
//                svd: STEM_rows.exr and STEM_cols.exr (rank K: K tiles of
//                R x R side by side); sh-k: STEM_coeffs.exr (one R x R tile
//                per SH coefficient, or one row of R texels per coefficient
//                when reduced). sh-r has no texture (its coefficients are
//                constants of the GLSL).
//   STEM.glsl    vec3 brdf_factor_eval(vec3 wi, vec3 wo), the same formula as
//                eval(), for GL 3.3 / 4.5, GLES 3.0 and Vulkan.
//   STEM.json    sidecar: format "brdf-factor-factorization", format_version 1,
//                method "svd" | "sh-k" | "sh-r", describe() of the method, and
//                data, textures, glsl.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "factor/factorization.h"

namespace bf {

// Methods this export handles.
bool is_baseline_method(const std::string& method);

struct BaselineExportFiles {
  std::string sidecar, data, glsl;
  std::vector<std::string> textures;
};

// Writes the export of an SvdFactorization, ShkFactorization or
// ShrFactorization (its write_export_files). Throws std::invalid_argument for another kind or a
// non-finite value (naming it), std::runtime_error naming a path that cannot
// be written.
BaselineExportFiles write_baseline_export(const Factorization& f, const std::string& dir,
                                          const std::string& stem);

// The GLSL and textures of these results: Factorization::glsl() and
// viewer_data() (factor/factorization.h), defined in baseline_export.cpp.

// Reads an export back from its sidecar (the .f64 file relative to the
// sidecar's folder). Validates format, version, method, every field read, the
// data file's size against its blocks, finite values, and zeros outside the
// disk grid's mask. Every count is bounded before anything is allocated or
// read: sizes by the method's option ranges (svd resolution 2..256 and rank
// at most the masked texels; sh-k ShkOptions::kMax*; sh-r order
// 0..ShrOptions::kMaxOrder, view_order 0..kMaxViewOrder), data.values by the
// data-file cap (kMaxDataFileBytes / 8), each block by data.values, their sum
// equal to data.values, and data.values by the data file's size. The sidecar
// and the data file must be regular files (brdfs/file_check.h). Errors name
// the file, the field, what was expected and what was found.
std::shared_ptr<Factorization> load_baseline_export(const std::string& json_path);

// The "method" of a factorization sidecar ("" when the file is not a JSON
// object with a string method). Throws std::invalid_argument naming the path
// when it is not a regular file of at most kMaxTextFileBytes.
std::string sidecar_method(const std::string& json_path);

}  // namespace bf
