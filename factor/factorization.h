// Factorization: what every method (homomorphic fit, McCool, search, SVD, SH)
// returns. It is itself a Brdf (so metrics, renders and MERL export treat an
// approximation like any other BRDF), knows how many floats a renderer must
// store, and describes itself as JSON for the export sidecar.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "brdfs/brdf.h"

namespace bf {

class Factorization : public Brdf {
 public:
  // Method name as written in results.csv ("fit", "mccool", "search", "svd", "sh-k", ...).
  virtual std::string method() const = 0;
  // Floats a renderer must hold: texels x channels + per-term constants.
  virtual size_t storage_floats() const = 0;
  // Everything needed to rebuild and evaluate this approximation (without the
  // texel arrays, which the exporter writes as images). See factor/export.h.
  virtual nlohmann::json describe() const = 0;
};

using FactorizationPtr = std::shared_ptr<const Factorization>;

}  // namespace bf
