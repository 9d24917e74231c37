// Sample-list CSV reader and writer (see sample_csv.h).
#include "brdfs/file_check.h"

#include "brdfs/temp_file.h"
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
#include "brdfs/measured_text.h"

namespace bf {

namespace {

constexpr size_t kMaxLine = 1 << 16;
const char* const kHeader[] = {"theta_i", "phi_i", "theta_o", "phi_o", "r", "g", "b", "weight"};

std::vector<std::string> split_commas(const std::string& line) {
  std::vector<std::string> cells;
  size_t start = 0;
  for (;;) {
    const size_t p = line.find(',', start);
    cells.push_back(
        text::strip(line.substr(start, p == std::string::npos ? std::string::npos : p - start)));
    if (p == std::string::npos) break;
    start = p + 1;
  }
  return cells;
}

// Spherical angles for writing; a non-finite direction (masked) is written as
// theta = pi, which reads back as below the horizon, so it stays masked.
void angles_for_csv(const Vec3& w, double& theta, double& phi) {
  if (!w.allFinite()) {
    theta = M_PI;
    phi = 0.0;
    return;
  }
  to_spherical(w, theta, phi);
}

}  // namespace

SampleSet read_sample_csv(const std::string& path) {
  check_regular_file(path, kMaxDataFileBytes, "sample list");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path + ": cannot open sample list");
  SampleSet s;
  std::string line;
  size_t lineno = 0;
  bool have_header = false, has_weight = false;
  while (text::read_line(in, line, kMaxLine, path, lineno + 1)) {
    ++lineno;
    if (lineno == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // UTF-8 BOM
    const std::string t = text::strip(line);
    if (t.empty() || t[0] == '#') continue;
    const auto cells = split_commas(t);
    const std::string where = text::where(path, lineno);
    if (!have_header) {
      if (cells.size() != 7 && cells.size() != 8)
        throw std::invalid_argument(where +
                                    ": expected header theta_i,phi_i,theta_o,phi_o,r,g,b"
                                    "[,weight], found " +
                                    std::to_string(cells.size()) +
                                    " columns: " + text::excerpt(t, 80));
      for (size_t c = 0; c < cells.size(); ++c)
        if (cells[c] != kHeader[c])
          throw std::invalid_argument(where + ": header column " + std::to_string(c + 1) +
                                      " expected '" + kHeader[c] + "', found " +
                                      text::excerpt(cells[c]));
      has_weight = cells.size() == 8;
      have_header = true;
      continue;
    }
    const size_t ncol = has_weight ? 8 : 7;
    if (cells.size() != ncol)
      throw std::invalid_argument(where + ": expected " + std::to_string(ncol) +
                                  " columns (as in the header), found " +
                                  std::to_string(cells.size()));
    double v[8];
    for (size_t c = 0; c < ncol; ++c)
      if (!text::parse_number(cells[c], v[c]))
        throw std::invalid_argument(where + ": column " + std::to_string(c + 1) + " (" +
                                    kHeader[c] + ") expected a number, found " +
                                    text::excerpt(cells[c]));
    for (int c = 0; c < 4; ++c) {
      const bool theta = (c % 2) == 0;
      const double lo = theta ? 0.0 : -2.0 * M_PI, hi = theta ? M_PI : 2.0 * M_PI;
      if (!(v[c] >= lo && v[c] <= hi))
        throw std::invalid_argument(where + ": " + kHeader[c] + " expected radians in [" +
                                    (theta ? "0, pi" : "-2pi, 2pi") + "], found " + cells[c]);
    }
    if (s.size() >= kMaxCsvSamples)
      throw std::invalid_argument(where + ": expected at most " + std::to_string(kMaxCsvSamples) +
                                  " samples, found more");
    s.push(from_spherical(v[0], v[1]), from_spherical(v[2], v[3]), Rgb(v[4], v[5], v[6]),
           has_weight ? v[7] : 1.0);
  }
  if (!have_header)
    throw std::invalid_argument(path +
                                ": expected a header line theta_i,phi_i,theta_o,phi_o,r,g,b"
                                "[,weight], found an empty file (or only comments)");
  if (s.size() == 0)
    throw std::invalid_argument(path +
                                ": expected at least one sample after the header, found "
                                "none");
  if (has_weight && s.weight.empty()) s.weight.assign(s.size(), 1.0);
  s.description = "sample list " + path;
  s.validate();
  return s;
}

void write_sample_csv(const SampleSet& s, const std::string& path) {
  const bool w = !s.weight.empty();
  if (w && s.weight.size() != s.size())
    throw std::invalid_argument(path + ": sample set has " + std::to_string(s.size()) +
                                " samples but " + std::to_string(s.weight.size()) + " weights");
  std::string desc = s.description;
  for (char& c : desc)
    if (c == '\n' || c == '\r') c = ' ';
  const std::string tmp = create_unique_temp(path);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(path + ": cannot open " + tmp + " for writing");
    out << "# " << desc << "\n";
    out << "theta_i,phi_i,theta_o,phi_o,r,g,b" << (w ? ",weight" : "") << "\n";
    out << std::setprecision(17);
    for (size_t k = 0; k < s.size(); ++k) {
      double ti, pi, to, po;
      angles_for_csv(s.wi[k], ti, pi);
      angles_for_csv(s.wo[k], to, po);
      out << ti << "," << pi << "," << to << "," << po;
      for (int c = 0; c < 3; ++c) {
        const double v = s.value[k][c];
        out << "," << (std::isfinite(v) ? v : -1.0);
      }
      if (w) out << "," << (std::isfinite(s.weight[k]) ? s.weight[k] : -1.0);
      out << "\n";
    }
    out.flush();
    if (!out) {
      out.close();
      std::remove(tmp.c_str());
      throw std::runtime_error(path + ": write failed (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot rename temporary file: " + ec.message());
  }
}

}  // namespace bf
