// Registers every analytic model with the catalogue.
#include "brdfs/catalogue.h"
#include "brdfs/models.h"

namespace bf {

void register_analytic_models(Catalogue& cat) { register_lambert(cat); }

}  // namespace bf
