// The defaults of Factorization's outputs (factor/factorization.h): none.
#include "factor/factorization.h"

#include <stdexcept>

namespace bf {

ExportedFiles Factorization::write_export_files(const std::string& dir, const std::string& stem,
                                                const std::string& origin) const {
  (void)dir, (void)stem, (void)origin;
  throw std::invalid_argument("export: method " + method() + " has no export (its result type defines none)");
}

std::string Factorization::glsl(const std::string& stem, const std::string& origin) const {
  (void)stem, (void)origin;
  throw std::invalid_argument("export: method " + method() + " has no GLSL (its result type defines none)");
}

}  // namespace bf
