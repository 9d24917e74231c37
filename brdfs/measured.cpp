// Loaders for measured BRDF files.
#include "brdfs/catalogue.h"

namespace bf {

void register_measured_loaders(Catalogue& cat) {}

}  // namespace bf
