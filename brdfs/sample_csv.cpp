// Sample-list CSV reader and writer (see sample_csv.h).
#include "brdfs/sample_csv.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "brdfs/directions.h"

namespace bf {

namespace {
std::string strip(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

std::vector<std::string> split_commas(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  std::string c;
  while (std::getline(ss, c, ',')) cells.push_back(strip(c));
  if (!line.empty() && line.back() == ',') cells.push_back("");
  return cells;
}
}  // namespace

SampleSet read_sample_csv(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path + ": cannot open sample list");
  static const char* kHeader[] = {"theta_i", "phi_i", "theta_o", "phi_o", "r", "g", "b"};
  SampleSet s;
  std::string line;
  size_t lineno = 0;
  bool have_header = false, has_weight = false;
  constexpr size_t kMaxLine = 1 << 16;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.size() > kMaxLine)
      throw std::invalid_argument(path + ":" + std::to_string(lineno) +
                                  ": line longer than 65536 characters");
    const std::string t = strip(line);
    if (t.empty() || t[0] == '#') continue;
    const auto cells = split_commas(t);
    const std::string where = path + ":" + std::to_string(lineno);
    if (!have_header) {
      if (cells.size() != 7 && cells.size() != 8)
        throw std::invalid_argument(where + ": expected header theta_i,phi_i,theta_o,phi_o,r,g,b"
                                            "[,weight], found " +
                                    std::to_string(cells.size()) + " columns");
      for (int c = 0; c < 7; ++c)
        if (cells[c] != kHeader[c])
          throw std::invalid_argument(where + ": header column " + std::to_string(c + 1) +
                                      " should be '" + kHeader[c] + "', found '" + cells[c] + "'");
      if (cells.size() == 8) {
        if (cells[7] != "weight")
          throw std::invalid_argument(where + ": header column 8 should be 'weight', found '" +
                                      cells[7] + "'");
        has_weight = true;
      }
      have_header = true;
      continue;
    }
    const size_t ncol = has_weight ? 8 : 7;
    if (cells.size() != ncol)
      throw std::invalid_argument(where + ": expected " + std::to_string(ncol) +
                                  " columns, found " + std::to_string(cells.size()));
    double v[8];
    for (size_t c = 0; c < ncol; ++c) {
      const std::string& cell = cells[c];
      size_t pos = 0;
      bool ok = !cell.empty();
      if (ok) {
        try {
          v[c] = std::stod(cell, &pos);
          ok = pos == cell.size();
        } catch (const std::out_of_range&) {
          v[c] = cell[0] == '-' ? -HUGE_VAL : HUGE_VAL;  // overflow: masked as invalid below
          ok = true;
        } catch (const std::exception&) {
          ok = false;
        }
      }
      if (!ok)
        throw std::invalid_argument(where + ": column " + std::to_string(c + 1) +
                                    " expected a number, found '" + cell + "'");
    }
    for (int c = 0; c < 4; ++c) {
      const bool theta = (c % 2) == 0;
      const double lo = theta ? 0.0 : -2.0 * M_PI, hi = theta ? M_PI : 2.0 * M_PI;
      if (!(v[c] >= lo && v[c] <= hi))
        throw std::invalid_argument(where + ": " + kHeader[c] + " must be in [" +
                                    (theta ? "0, pi" : "-2pi, 2pi") + "] radians, found " +
                                    cells[c]);
    }
    s.push(from_spherical(v[0], v[1]), from_spherical(v[2], v[3]), Rgb(v[4], v[5], v[6]),
           has_weight ? v[7] : 1.0);
  }
  if (!have_header) throw std::invalid_argument(path + ": empty sample list (no header line)");
  if (s.size() == 0) throw std::invalid_argument(path + ": header but no samples");
  if (has_weight && s.weight.empty()) s.weight.assign(s.size(), 1.0);
  s.description = "sample list " + path;
  s.validate();
  return s;
}

void write_sample_csv(const SampleSet& s, const std::string& path) {
  const bool w = !s.weight.empty();
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw std::runtime_error(path + ": cannot open for writing");
    out << "# " << s.description << "\n";
    out << "theta_i,phi_i,theta_o,phi_o,r,g,b" << (w ? ",weight" : "") << "\n";
    out << std::setprecision(17);
    for (size_t k = 0; k < s.size(); ++k) {
      double ti, pi, to, po;
      to_spherical(s.wi[k], ti, pi);
      to_spherical(s.wo[k], to, po);
      out << ti << "," << pi << "," << to << "," << po << "," << s.value[k][0] << ","
          << s.value[k][1] << "," << s.value[k][2];
      if (w) out << "," << s.weight[k];
      out << "\n";
    }
    out.flush();
    if (!out) {
      std::remove(tmp.c_str());
      throw std::runtime_error(path + ": write failed (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error(path + ": cannot rename temporary file: " + ec.message());
}

}  // namespace bf
