// The tabulating kinds' resampling note (see tabulating.h).
#include "experiments/methods/tabulating.h"

#include "brdfs/merl.h"
#include "factor/export.h"
#if __has_include("brdfs/measured.h")
#include "brdfs/measured.h"
#define BF_HAVE_MEASURED 1
#endif

namespace bf {

std::string resampling_note(const Brdf& brdf) {
#ifdef BF_HAVE_MEASURED
  if (const auto* mb = dynamic_cast<const MeasuredBrdf*>(&brdf))
    return "resampled: tabulated from the modified Shepard interpolant (k = " +
           std::to_string(mb->options().neighbours) + ", Marschner space) of " +
           std::to_string(mb->samples().size()) + " measured samples";
#endif
  if (const auto* mb = dynamic_cast<const MerlBrdf*>(&brdf))
    return std::string("resampled: tabulated from the MERL table by ") +
           (mb->lookup() == MerlLookup::Linear ? "trilinear interpolation of bin centres" : "nearest bin");
  return "";
}

void add_resampling_note(const RunContext& c, MethodOutcome& out) {
  if (const std::string how = resampling_note(*c.brdf.brdf); !how.empty()) out.notes.push_back(how);
}

void export_tabulated(const RunContext& c, const MethodOutcome& out) {
  write_description(c, out);
  write_export(*out.result, c.run_dir.string(), "factors");
}

}  // namespace bf
