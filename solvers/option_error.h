// The error an options struct's validate() throws: an std::invalid_argument
// that also carries the option's name, so that a caller reading the options
// from a file (experiments/config/config.cpp) reports the problem at that key's
// file:line. what() is the full message, "<field>: <rule>, found <value>".
#pragma once

#include <stdexcept>
#include <string>

namespace bf {

class OptionError : public std::invalid_argument {
 public:
  OptionError(std::string field, const std::string& message)
      : std::invalid_argument(message), field_(std::move(field)) {}
  // The option's name as the config spells it, e.g. "lobes".
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

}  // namespace bf
