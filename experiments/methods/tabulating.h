// What the tabulating kinds (svd, sh-k, sh-r) share: they read a BRDF at their
// own grid or quadrature nodes, so for measured data off its interpolant.
#pragma once

#include "experiments/common/cli_util.h"
#include "experiments/methods/method_kind.h"

namespace bf {

// How a tabulating method reads `brdf` when it is measured data (the
// interpolation between measurements); "" for analytic BRDFs.
std::string resampling_note(const Brdf& brdf);
// Appends resampling_note(c.brdf) to out.notes when there is one.
void add_resampling_note(const RunContext& c, MethodOutcome& out);
// The export of a tabulating kind: factorization.json (its description) and
// the loadable export factors.json + factors.f64 + textures + factors.glsl
// (factor/baseline_export.h), which `--brdf factors.json` reloads.
void export_tabulated(const RunContext& c, const MethodOutcome& out);

}  // namespace bf
