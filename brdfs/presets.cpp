// Named presets (pbrt-v1 Lafortune materials, Ngan 2005 fits).
#include "brdfs/catalogue.h"

namespace bf {

void register_presets(Catalogue& cat) {}

}  // namespace bf
