// Named presets: pbrt-v1's measured Lafortune materials and the Ngan et al.
// 2005 fits to MERL, read from data/params/*.csv, plus Cole's Cook-Torrance.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "brdfs/catalogue.h"
#include "brdfs/models.h"

namespace bf {

namespace {

// A parsed CSV table: header plus rows of raw cells (numbers kept verbatim, so
// preset strings carry exactly the published digits).
struct CsvTable {
  std::string path;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> lines;  // 1-based file line of each row

  [[noreturn]] void fail(int line, const std::string& what) const {
    throw std::runtime_error(path + ":" + std::to_string(line) + ": " + what);
  }
  int column(const std::string& name) const {
    for (size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return static_cast<int>(i);
    fail(1, "expected a column '" + name + "' in the header");
  }
  // Cell of row r in column `name`, checked to be a finite number.
  std::string number(size_t r, const std::string& name) const {
    const std::string& s = rows[r][column(name)];
    double v = 0;
    size_t pos = 0;
    bool ok = !s.empty();
    if (ok) {
      try {
        v = std::stod(s, &pos);
      } catch (const std::exception&) {
        ok = false;
      }
    }
    if (!ok || pos != s.size() || !std::isfinite(v))
      fail(lines[r], "column '" + name + "': expected a finite number, found '" + s + "'");
    return s;
  }
  std::string rgb(size_t r, const std::string& stem) const {
    return number(r, stem + "_r") + "/" + number(r, stem + "_g") + "/" + number(r, stem + "_b");
  }
};

// Reads path into t. Returns false when the file does not exist; throws
// std::runtime_error naming file and line when it is malformed.
bool read_csv(const std::string& path, CsvTable& t) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) return false;
  constexpr std::uintmax_t kMaxBytes = 16u << 20;  // the tables are a few kB
  const auto size = fs::file_size(path, ec);
  t.path = path;
  if (ec) t.fail(0, "cannot read the file size: " + ec.message());
  if (size > kMaxBytes)
    t.fail(0, "expected a parameter table of at most 16 MiB, file has " + std::to_string(size) +
                  " bytes");
  std::ifstream in(path);
  if (!in) t.fail(0, "cannot open the file");
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.push_back("");
    if (t.header.empty()) {
      t.header = cells;
      continue;
    }
    if (cells.size() != t.header.size())
      t.fail(n, "expected " + std::to_string(t.header.size()) + " fields as in the header, found " +
                    std::to_string(cells.size()));
    if (cells[0].empty()) t.fail(n, "expected a material name in the first field");
    t.rows.push_back(std::move(cells));
    t.lines.push_back(n);
  }
  if (t.header.empty()) t.fail(1, "expected a header line, the file is empty");
  return true;
}

// pbrt-v1's Lafortune materials, long format material,lobe,param,r,g,b:
// lobe "diffuse" holds rho_d, lobes 0, 1, 2 hold Cxy, Cz, n (Cx = Cy = Cxy).
void add_pbrt_v1(Catalogue& cat, const std::string& dir) {
  CsvTable t;
  const std::string file = "pbrt_v1_lafortune_materials.csv";
  if (!read_csv(dir + "/" + file, t)) return;
  for (const char* col : {"material", "lobe", "param"}) t.column(col);
  struct Material {
    std::string rho_d;
    std::map<int, std::map<std::string, std::string>> lobes;
    int line = 0;
  };
  std::vector<std::string> order;
  std::map<std::string, Material> mats;
  for (size_t r = 0; r < t.rows.size(); ++r) {
    const std::string& name = t.rows[r][t.column("material")];
    const std::string& lobe = t.rows[r][t.column("lobe")];
    const std::string& param = t.rows[r][t.column("param")];
    if (!mats.count(name)) {
      order.push_back(name);
      mats[name].line = t.lines[r];
    }
    Material& m = mats[name];
    const std::string value = t.number(r, "r") + "/" + t.number(r, "g") + "/" + t.number(r, "b");
    if (lobe == "diffuse") {
      if (param != "rho_d")
        t.fail(t.lines[r], "diffuse rows take param rho_d, found '" + param + "'");
      if (!m.rho_d.empty()) t.fail(t.lines[r], "second rho_d row for " + name);
      m.rho_d = value;
      continue;
    }
    if (lobe.empty() || lobe.size() > 2 ||
        lobe.find_first_not_of("0123456789") != std::string::npos)
      t.fail(t.lines[r], "lobe: expected 'diffuse' or a lobe index 0..99, found '" + lobe + "'");
    if (param != "Cxy" && param != "Cz" && param != "n")
      t.fail(t.lines[r], "lobe rows take param Cxy, Cz or n, found '" + param + "'");
    auto& slot = m.lobes[std::stoi(lobe)][param];
    if (!slot.empty()) t.fail(t.lines[r], "second " + param + " row for " + name + " lobe " + lobe);
    slot = value;
  }
  for (const std::string& name : order) {
    const Material& m = mats[name];
    std::string params = "rho_d=" + (m.rho_d.empty() ? std::string("0") : m.rho_d);
    int expect = 0;
    for (const auto& [k, lobe] : m.lobes) {
      if (k != expect)
        t.fail(m.line, name + ": lobes must be numbered 0, 1, ... without gaps, missing lobe " +
                           std::to_string(expect));
      for (const char* p : {"Cxy", "Cz", "n"})
        if (!lobe.count(p))
          t.fail(m.line, name + " lobe " + std::to_string(k) + " has no " + p + " row");
      const std::string s = std::to_string(k);
      params += ",cxy" + s + "=" + lobe.at("Cxy") + ",cz" + s + "=" + lobe.at("Cz") + ",n" + s +
                "=" + lobe.at("n");
      ++expect;
    }
    if (m.rho_d.empty()) t.fail(m.line, name + " has no diffuse rho_d row");
    cat.add_preset({name, "lafortune", params + ",normalization=none",
                    "pbrt-v1 materials/" + name +
                        ".cpp, unnormalized lobes as pbrt-v1 "
                        "Lafortune::f; data/params/" +
                        file});
  }
}

// One Ngan et al. 2005 table: columns material, kd_{rgb}, albedo_{rgb}, then
// the model's own; `build` maps a row to the preset's parameter string.
struct NganFamily {
  const char* file;    // e.g. "ngan2005_ward.csv"
  const char* prefix;  // preset name prefix, e.g. "ngan-ward"
  const char* model;
  std::string (*build)(const CsvTable& t, size_t r);
};

const NganFamily kNgan[] = {
    {"ngan2005_ward.csv", "ngan-ward", "ward",
     [](const CsvTable& t, size_t r) {
       const std::string a = t.number(r, "roughness");
       return "kd=" + t.rgb(r, "kd") + ",ks=" + t.rgb(r, "albedo") + ",ax=" + a + ",ay=" + a +
              ",variant=ward";
     }},
    {"ngan2005_wardduer.csv", "ngan-ward-duer", "ward",
     [](const CsvTable& t, size_t r) {
       const std::string a = t.number(r, "roughness");
       return "kd=" + t.rgb(r, "kd") + ",ks=" + t.rgb(r, "albedo") + ",ax=" + a + ",ay=" + a +
              ",variant=duer";
     }},
    // bbm aliases Ngan's Blinn-Phong to a mirror-vector Phong lobe; we use the
    // half vector with (n+2)/(2 pi), which is what the fitted numbers fit:
    // against the Ward fits of the same materials the median of n * alpha^2 is
    // 2.6 (half vector predicts ~2, mirror ~0.5) and the median rho_s ratio is
    // 0.23 (half vector with this constant predicts ~1/4, mirror ~1).
    {"ngan2005_blinnphong.csv", "ngan-blinn-phong", "blinn-phong",
     [](const CsvTable& t, size_t r) {
       return "kd=" + t.rgb(r, "kd") + ",ks=" + t.rgb(r, "albedo") +
              ",n=" + t.number(r, "sharpness") + ",normalization=ngan";
     }},
    // The `eta` column holds Schlick's F0, not an index of refraction.
    {"ngan2005_cooktorrance.csv", "ngan-cook-torrance", "cook-torrance",
     [](const CsvTable& t, size_t r) {
       return "kd=" + t.rgb(r, "kd") + ",ks=" + t.rgb(r, "albedo") +
              ",m=" + t.number(r, "roughness") + ",fresnel=schlick,f0=" + t.number(r, "eta") +
              ",form=ngan";
     }},
    {"ngan2005_ashikhminshirley.csv", "ngan-ashikhmin-shirley", "ashikhmin-shirley",
     [](const CsvTable& t, size_t r) {
       const std::string n = t.number(r, "sharpness");
       return "rd=" + t.rgb(r, "kd") + ",ks=" + t.rgb(r, "albedo") +
              ",rs=" + t.number(r, "fresnelReflectance") + ",nu=" + n + ",nv=" + n +
              ",diffuse=lambert";
     }},
    {"ngan2005_lafortune.csv", "ngan-lafortune", "lafortune",
     [](const CsvTable& t, size_t r) {
       return "rho_d=" + t.rgb(r, "kd") + ",ks0=" + t.rgb(r, "albedo") +
              ",cxy0=" + t.number(r, "Cxy") + ",cz0=" + t.number(r, "Cz") +
              ",n0=" + t.number(r, "sharpness") + ",normalization=ngan";
     }},
};

void add_ngan(Catalogue& cat, const std::string& dir, const NganFamily& fam) {
  CsvTable t;
  if (!read_csv(dir + "/" + fam.file, t)) return;
  std::set<std::string> seen;
  for (size_t r = 0; r < t.rows.size(); ++r) {
    const std::string& mat = t.rows[r][0];
    if (!seen.insert(mat).second) t.fail(t.lines[r], "second row for material '" + mat + "'");
    const std::string stem = std::string(fam.file).substr(0, std::string(fam.file).size() - 4);
    cat.add_preset({std::string(fam.prefix) + "/" + mat, fam.model, fam.build(t, r),
                    std::string("Ngan et al. 2005 fit to MERL ") + mat + ", bbm fits/ngan_" +
                        stem.substr(9) + ".fit; data/params/" + fam.file});
  }
}

}  // namespace

void register_presets_from(Catalogue& cat, const std::string& params_dir) {
  // Cole 2002 §4.1 tested "a general Cook-Torrance function as described in
  // Foley et al."; the parameters are the foundation issue's.
  cat.add_preset({"cole-cook-torrance", "cook-torrance",
                  "kd=0.1,ks=0.9,m=0.3,fresnel=schlick,f0=0.1,form=foley",
                  "Cole 2002 thesis §4.1 Cook-Torrance test BRDF in the Foley et al. form; "
                  "Beckmann m 0.3, kd 0.1, ks 0.9, Schlick F0 0.1"});
  add_pbrt_v1(cat, params_dir);
  for (const NganFamily& fam : kNgan) add_ngan(cat, params_dir, fam);
}

void register_presets(Catalogue& cat) {
  register_presets_from(cat, data_dir() + "/params");
}

}  // namespace bf
