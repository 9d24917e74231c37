// ParamDict implementation (see params.h).
#include "brdfs/params.h"

#include <cmath>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace bf {

namespace {
// strtod, not std::stod: stod throws out_of_range for an underflow such as
// 1e-320 (a denormal, a valid number that validation then judges), which
// read as "expects one number".
bool parse_double(const std::string& s, double& out) {
  if (s.empty() || std::isspace(static_cast<unsigned char>(s[0]))) return false;
  char* end = nullptr;
  errno = 0;
  out = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size()) return false;
  return std::isfinite(out) && (errno != ERANGE || std::abs(out) < 1.0);
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}
}  // namespace

void ParamDict::set_numbers(const std::string& key, std::vector<double> values) {
  if (values.empty()) throw std::invalid_argument(origin_ + ": parameter '" + key + "' has no value");
  for (double v : values)
    if (!std::isfinite(v))
      throw std::invalid_argument(origin_ + ": parameter '" + key + "' must be finite");
  Value v;
  v.numbers = std::move(values);
  values_[key] = v;
}

void ParamDict::set_string(const std::string& key, std::string value) {
  Value v;
  v.text = std::move(value);
  v.is_text = true;
  values_[key] = v;
}

void ParamDict::parse_assignments(const std::string& text) {
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    item = trim(item);
    if (item.empty()) continue;
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq == 0)
      throw std::invalid_argument(origin_ + ": expected key=value, found '" + item + "'");
    const std::string key = trim(item.substr(0, eq));
    const std::string val = trim(item.substr(eq + 1));
    if (val.empty())
      throw std::invalid_argument(origin_ + ": parameter '" + key + "' has an empty value");
    std::vector<double> nums;
    std::stringstream vs(val);
    std::string part;
    bool all_numeric = true;
    while (std::getline(vs, part, '/')) {
      double d;
      if (!parse_double(trim(part), d)) {
        all_numeric = false;
        break;
      }
      nums.push_back(d);
    }
    if (all_numeric) {
      if (nums.size() != 1 && nums.size() != 3)
        throw std::invalid_argument(origin_ + ": parameter '" + key +
                                    "' expects 1 number or r/g/b, found '" + val + "'");
      set_numbers(key, nums);
    } else {
      set_string(key, val);
    }
  }
}

void ParamDict::merge_defaults_from(const ParamDict& other) {
  for (const auto& [k, v] : other.values_) {
    if (values_.count(k)) continue;
    Value copy = v;
    copy.used = false;
    values_[k] = copy;
  }
}

const ParamDict::Value* ParamDict::find(const std::string& key) const {
  auto it = values_.find(key);
  if (it == values_.end()) return nullptr;
  it->second.used = true;
  return &it->second;
}

double ParamDict::get_scalar(const std::string& key, double def) const {
  const Value* v = find(key);
  if (!v) return def;
  if (v->is_text || v->numbers.size() != 1)
    throw std::invalid_argument(origin_ + ": parameter '" + key + "' expects one number, found " +
                                (v->is_text ? "'" + v->text + "'"
                                            : std::to_string(v->numbers.size()) + " numbers"));
  return v->numbers[0];
}

Rgb ParamDict::get_rgb(const std::string& key, const Rgb& def) const {
  const Value* v = find(key);
  if (!v) return def;
  if (v->is_text || (v->numbers.size() != 1 && v->numbers.size() != 3))
    throw std::invalid_argument(origin_ + ": parameter '" + key +
                                "' expects one number or r/g/b, found " +
                                (v->is_text ? "'" + v->text + "'"
                                            : std::to_string(v->numbers.size()) + " numbers"));
  if (v->numbers.size() == 1) return Rgb::Constant(v->numbers[0]);
  return Rgb(v->numbers[0], v->numbers[1], v->numbers[2]);
}

int ParamDict::get_int(const std::string& key, int def) const {
  const double d = get_scalar(key, def);
  if (d != std::floor(d) || std::abs(d) > 1e9)
    throw std::invalid_argument(origin_ + ": parameter '" + key + "' expects an integer, found " +
                                std::to_string(d));
  return static_cast<int>(d);
}

std::vector<double> ParamDict::get_list(const std::string& key,
                                        const std::vector<double>& def) const {
  const Value* v = find(key);
  if (!v) return def;
  if (v->is_text)
    throw std::invalid_argument(origin_ + ": parameter '" + key + "' expects numbers, found '" +
                                v->text + "'");
  return v->numbers;
}

std::string ParamDict::get_string(const std::string& key, const std::string& def) const {
  const Value* v = find(key);
  if (!v) return def;
  if (!v->is_text)
    throw std::invalid_argument(origin_ + ": parameter '" + key + "' expects a word, found a number");
  return v->text;
}

void ParamDict::check_unused(const std::string& model,
                             const std::vector<std::string>& accepted) const {
  for (const auto& [k, v] : values_) {
    if (!v.used) {
      std::string acc;
      for (const auto& a : accepted) acc += (acc.empty() ? "" : ", ") + a;
      throw std::invalid_argument(origin_ + ": unknown parameter '" + k + "' for " + model +
                                  " (accepted: " + (acc.empty() ? "none" : acc) + ")");
    }
  }
}

std::vector<std::string> ParamDict::keys() const {
  std::vector<std::string> k;
  for (const auto& [key, v] : values_) k.push_back(key);
  return k;
}

}  // namespace bf
