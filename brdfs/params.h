// A dictionary of named BRDF parameters that remembers which keys were read, so
// that a key nobody used is reported as an error (pbrt-v4 ReportUnused style).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "brdfs/brdf.h"

namespace bf {

class ParamDict {
 public:
  // origin: where the values came from, used in messages ("--brdf", "exp.toml:12").
  explicit ParamDict(std::string origin = "parameters") : origin_(std::move(origin)) {}

  // Numbers: 1 value (scalar, broadcast to RGB) or 3 values (RGB).
  void set_numbers(const std::string& key, std::vector<double> values);
  void set_string(const std::string& key, std::string value);
  // Parses "k=v,k=v" where v is a number, r/g/b (three numbers), or a word.
  // Throws std::invalid_argument naming the malformed item.
  void parse_assignments(const std::string& text);
  // Copies every key of `other` that this dict does not have (preset defaults).
  void merge_defaults_from(const ParamDict& other);

  bool has(const std::string& key) const { return values_.count(key) != 0; }
  // Each getter marks the key used; missing keys return the default.
  double get_scalar(const std::string& key, double def) const;
  Rgb get_rgb(const std::string& key, const Rgb& def) const;
  int get_int(const std::string& key, int def) const;
  std::vector<double> get_list(const std::string& key, const std::vector<double>& def) const;
  std::string get_string(const std::string& key, const std::string& def) const;

  // Throws std::invalid_argument if any key was never read, naming it, the
  // model and the accepted keys.
  void check_unused(const std::string& model, const std::vector<std::string>& accepted) const;
  const std::string& origin() const { return origin_; }
  std::vector<std::string> keys() const;

 private:
  struct Value {
    std::vector<double> numbers;
    std::string text;
    bool is_text = false;
    mutable bool used = false;
  };
  const Value* find(const std::string& key) const;
  std::string origin_;
  std::map<std::string, Value> values_;
};

}  // namespace bf
