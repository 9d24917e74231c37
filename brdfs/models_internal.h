// Helpers shared by the model sources (brdfs/models_*.cpp) and the model
// fit's parser (factor/model_fit.cpp): number formatting, range checks and
// choice parsing with messages naming the model and key. Not part of the
// library's public interface (brdfs/models.h).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "brdfs/brdf.h"
#include "brdfs/params.h"

namespace bf {

namespace detail {
// Shortest round-trip decimal ("0.25"); RGB as "r/g/b", or one number when
// all channels are equal, so to_string() output can be pasted back as a spec.
std::string fmt(double v);
std::string fmt(const Rgb& v);
// Throws std::invalid_argument "<model>: <key> = <value> is out of range: must
// be <rule>" unless ok.
void require(bool ok, const std::string& model, const std::string& key, const std::string& value,
             const std::string& rule);
void require_nonneg(const std::string& model, const std::string& key, const Rgb& v);
void require_nonneg(const std::string& model, const std::string& key, double v);
void require_positive(const std::string& model, const std::string& key, double v);
// Reads the word `key` from d (choices[def] when absent) and returns its index
// in choices; throws std::invalid_argument "<origin>: <model>: <key> =
// '<value>' is not one of a, b, c" otherwise.
int parse_choice(const ParamDict& d, const std::string& model, const std::string& key, int def,
                 const std::vector<std::string>& choices);
// Builds T from p, prefixing validation messages with the dict's origin
// ("--brdf: ward: ax = ..."), so the user sees where the value came from.
template <class T, class P>
BrdfPtr make_checked(const ParamDict& d, const P& p) {
  try {
    return std::make_shared<T>(p);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(d.origin() + ": " + e.what());
  }
}
}  // namespace detail

}  // namespace bf
