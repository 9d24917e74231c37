// CLI helpers (see cli_util.h).
#include "experiments/common/cli_util.h"

#include "brdfs/temp_file.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace bf {

Vec3 parse_direction(const std::string& text, const std::string& what) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, ',')) {
    char* end = nullptr;
    errno = 0;
    const double d = std::strtod(part.c_str(), &end);  // an underflow (1e-320) is a number
    if (part.empty() || end != part.c_str() + part.size() || !std::isfinite(d) ||
        (errno == ERANGE && std::abs(d) >= 1.0))
      throw std::invalid_argument(what + ": expected three finite numbers x,y,z, found '" + text + "'");
    v.push_back(d);
  }
  if (v.size() != 3)
    throw std::invalid_argument(what + ": expected three numbers x,y,z, found " +
                                std::to_string(v.size()) + " in '" + text + "'");
  Vec3 w(v[0], v[1], v[2]);
  const double n = w.norm();
  if (!(n > 1e-12)) throw std::invalid_argument(what + ": direction must be non-zero");
  return w / n;
}

void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& body) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  if (p.has_parent_path()) {
    std::error_code ec;
    fs::create_directories(p.parent_path(), ec);
    if (ec)
      throw std::runtime_error(path + ": cannot create folder " + p.parent_path().string() + ": " +
                               ec.message());
  }
  const std::string tmp = create_unique_temp(path);
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw std::runtime_error(path + ": cannot open for writing");
    body(out);
    out.flush();
    if (!out) {
      std::remove(tmp.c_str());
      throw std::runtime_error(path + ": write failed (disk full?)");
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot rename temporary file: " + ec.message());
  }
}

bool write_file_if_changed(const std::string& path, const std::function<void(std::ostream&)>& body) {
  namespace fs = std::filesystem;
  std::ostringstream o;
  body(o);
  const std::string text = o.str();
  std::error_code ec;
  if (fs::is_regular_file(fs::symlink_status(path, ec)) && fs::file_size(path, ec) == text.size() && !ec) {
    std::ifstream in(path, std::ios::binary);
    std::string old(text.size(), '\0');
    if (in.read(old.data(), static_cast<std::streamsize>(old.size())) && in.peek() == std::char_traits<char>::eof() &&
        old == text)
      return false;
  }
  write_file_atomic(path, [&](std::ostream& out) { out << text; });
  return true;
}

std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
  return s;
}

}  // namespace bf
