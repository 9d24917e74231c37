// Experiment folder outputs (see outputs.h).
#include "experiments/report/outputs.h"

#include "brdfs/file_check.h"
#include "brdfs/safe_path.h"

#include <Eigen/Core>
#include <ceres/version.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <sys/wait.h>
#include <toml++/toml.h>

#include "experiments/common/cli_util.h"
#include "experiments/report/escape.h"
#include "experiments/report/plot_step.h"
#include "experiments/report/report.h"
#include "experiments/report/validation.h"
#include "factor/image_io.h"

namespace bf {

namespace fs = std::filesystem;
using nlohmann::json;

const std::vector<std::string>& required_columns() {
  static const std::vector<std::string> c = {
      "run_id",   "brdf",    "method",  "parameterization", "reciprocity", "terms",
      "texture_size", "samples", "rel_mse", "rel_mae", "rel_max", "lin_rmse",
      "lin_mae",  "lin_max", "cos_rmse", "storage_floats", "seconds", "evaluations"};
  return c;
}

const std::vector<std::string>& result_columns() {
  static const std::vector<std::string> c = [] {
    std::vector<std::string> v = required_columns();
    for (const char* e : {"label", "sampling", "sweep", "seed", "status", "errors_after_term",
                          "search_strategy", "search_samples", "term_parameterizations", "negative_texels",
                          "order", "view_order", "tolerance", "tolerance_reached", "shade_rmse", "scene_rel_mse",
                          "val_rel_mse", "val_cos_rmse", "val_max_ratio", "holdout_rel_mse", "holdout_cos_rmse", "validation",
                          "flag", "isotropic", "symmetries",
                          "refine", "refine_seconds", "rel_mse_before", "rel_mae_before", "rel_max_before",
                          "lin_rmse_before", "lin_mae_before", "lin_max_before", "cos_rmse_before", "model",
                          "sampler_storage", "sampler_build_s", "notes"})
      v.push_back(e);
    return v;
  }();
  return c;
}

std::vector<std::string> display_columns(const std::vector<RunEntry>& runs) {
  std::vector<std::string> cols = required_columns();
  cols.insert(cols.begin() + 3, "label");
  for (const char* extra : {"search_strategy", "term_parameterizations", "order", "view_order", "tolerance", "tolerance_reached", "shade_rmse", "scene_rel_mse",
                            "val_rel_mse", "val_cos_rmse", "val_max_ratio", "holdout_rel_mse", "holdout_cos_rmse", "flag", "refine",
                            "refine_seconds", "rel_mse_before", "lin_rmse_before", "cos_rmse_before", "seed",
                            "sampling", "sweep", "model", "notes"})
    for (const auto& r : runs) {
      auto it = r.row.find(extra);
      if (it != r.row.end() && !it->second.empty()) {
        cols.push_back(extra);
        break;
      }
    }
  return key_columns_first(cols);  // experiments/report/report.h
}

std::string format_number(double v) {
  if (!std::isfinite(v)) return "";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

std::string format_short(const std::string& cell) {
  if (cell.empty()) return cell;
  char* end = nullptr;
  const double v = std::strtod(cell.c_str(), &end);
  if (end == cell.c_str() || *end != '\0' || !std::isfinite(v)) return cell;
  if (cell.find_first_of(".eE") == std::string::npos) return cell;  // integers stay as they are
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// ------------------------------------------------------------------ CSV

namespace {

std::string csv_cell(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += "\"\"";
    else if (c == '\n' || c == '\r') q += ' ';
    else q += c;
  }
  return q + "\"";
}

std::vector<std::string> csv_split(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') cur += '"', ++i;
      else if (c == '"') quoted = false;
      else cur += c;
    } else if (c == '"') quoted = true;
    else if (c == ',') out.push_back(cur), cur.clear();
    else cur += c;
  }
  out.push_back(cur);
  return out;
}

}  // namespace

void write_results_csv(const std::string& path, const std::vector<Row>& rows) {
  write_file_atomic(path, [&](std::ostream& o) {
    const auto& cols = result_columns();
    for (size_t i = 0; i < cols.size(); ++i) o << (i ? "," : "") << cols[i];
    o << "\n";
    for (const Row& r : rows) {
      for (size_t i = 0; i < cols.size(); ++i) {
        auto it = r.find(cols[i]);
        o << (i ? "," : "") << csv_cell(it == r.end() ? "" : it->second);
      }
      o << "\n";
    }
  });
}

std::vector<Row> read_results_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot open");
  std::string line;
  if (!std::getline(in, line)) throw std::invalid_argument(path + ":1: expected a header line, file is empty");
  const auto header = csv_split(line);
  std::vector<Row> rows;
  int n = 1;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty()) continue;
    const auto cells = csv_split(line);
    if (cells.size() != header.size())
      throw std::invalid_argument(path + ":" + std::to_string(n) + ": expected " +
                                  std::to_string(header.size()) + " cells, found " + std::to_string(cells.size()));
    Row r;
    for (size_t i = 0; i < cells.size(); ++i) r[header[i]] = cells[i];
    rows.push_back(std::move(r));
  }
  return rows;
}

// ------------------------------------------------------------------ versions, python

namespace {

std::string run_capture(const std::string& cmd, int* status) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) {
    if (status) *status = -1;
    return out;
  }
  std::array<char, 4096> buf;
  size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  const int st = pclose(p);
  if (status) *status = st;
  return out;
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'') q += "'\\''";
    else q += c;
  }
  return q + "'";
}

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  return s;
}

// The first 1 MiB of a file ("" when it cannot be read).
std::string read_text_prefix(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string s(size_t(1) << 20, '\0');
  in.read(s.data(), std::streamsize(s.size()));
  s.resize(size_t(in.gcount()));
  return s;
}

}  // namespace

json software_versions() {
  json v;
  v["brdf_factor"] = kBrdfFactorVersion;
  const std::string src = BRDF_FACTOR_SOURCE_DIR;
  int st = 0;
  const std::string commit =
      trim(run_capture("git -C " + shell_quote(src) + " rev-parse --short=12 HEAD 2>/dev/null", &st));
  if (st == 0 && !commit.empty()) {
    v["git_commit"] = commit;
    const std::string dirty =
        trim(run_capture("git -C " + shell_quote(src) + " status --porcelain --untracked-files=no 2>/dev/null", &st));
    v["git_dirty"] = st == 0 && !dirty.empty();
  }
  v["eigen"] = std::to_string(EIGEN_WORLD_VERSION) + "." + std::to_string(EIGEN_MAJOR_VERSION) + "." +
               std::to_string(EIGEN_MINOR_VERSION);
  v["ceres"] = CERES_VERSION_STRING;
  v["openexr"] = openexr_version();
  v["libpng"] = libpng_version();
  v["tomlplusplus"] = std::to_string(TOML_LIB_MAJOR) + "." + std::to_string(TOML_LIB_MINOR) + "." +
                      std::to_string(TOML_LIB_PATCH);
  v["nlohmann_json"] = std::to_string(NLOHMANN_JSON_VERSION_MAJOR) + "." +
                       std::to_string(NLOHMANN_JSON_VERSION_MINOR) + "." +
                       std::to_string(NLOHMANN_JSON_VERSION_PATCH);
  v["compiler"] = __VERSION__;
  return v;
}

std::string find_python(std::string* why) {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("BRDF_FACTOR_PYTHON")) candidates.push_back(env);
  candidates.push_back("python3");
  candidates.push_back("/usr/bin/python3");
  std::string tried;
  for (const auto& c : candidates) {
    int st = 0;
    run_capture(shell_quote(c) + " -c 'import matplotlib' >/dev/null 2>&1", &st);
    if (st == 0) return c;
    tried += (tried.empty() ? "" : ", ") + c;
  }
  if (why)
    *why = "no python3 with matplotlib found (tried " + tried +
           "; install Debian's python3-matplotlib, or set BRDF_FACTOR_PYTHON)";
  return "";
}

std::string plot_script_path() {
  if (const char* env = std::getenv("BRDF_FACTOR_PLOT_SCRIPT")) return env;
  return std::string(BRDF_FACTOR_SOURCE_DIR) + "/experiments/report/plot_results.py";
}

// ------------------------------------------------------------------ results.md

namespace {

std::string now_iso() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

void write_results_md(const ExperimentOutput& e, const OutputFiles& f, const std::string& path) {
  const json& x = e.experiment;
  write_file_if_changed(path, [&](std::ostream& o) {  // unchanged: file and mtime kept
    // Text of user origin through md_text / md_code / url_path (escape.h).
    o << "# Experiment " << md_text(x.value("name", "")) << "\n\n";
    if (!x.value("description", "").empty()) o << md_text(x.value("description", "")) << "\n\n";
    size_t failed = 0;
    for (const auto& r : e.runs) failed += r.status != "ok";
    o << "- config: [config.toml](config.toml) (from " << md_code(e.config_path) << ")";
    for (const auto& d : e.defines) o << ", " << md_code("-D " + d);
    o << "\n- runs: " << e.runs.size() << " in this folder";
    if (e.shards > 1) o << " (shard " << e.shard << "/" << e.shards << " of " << e.plan.size() << ")";
    if (!e.merged_from.empty()) o << " (merged from " << e.merged_from.size() << " shard folders)";
    if (failed) o << ", **" << failed << " failed**";
    o << "\n- seed: " << md_text(x.value("seed", json(1)).dump()) << " (per-run seeds in manifest.json)\n";
    o << "- errors: docs/design.md §4 on each run's samples (log transform eps "
      << md_text(x.value("metric_eps", json(1e-5)).dump()) << "); `seconds` is the method's wall time\n";
    o << "- validation: `val_*` on a stratified whole-domain set against the BRDF (measured: its interpolant), "
         "`holdout_*` on raw samples held out of the fit, `shade_rmse` in the scene (docs/design.md §4.1); "
         "`flag`: validation error > "
      << format_number(kFlagErrorFactor) << "x training and > " << format_number(kFlagErrorFloor)
      << ", or `val_max_ratio` > " << format_number(kFlagMaxRatio) << " (reason in notes)\n";
    o << "- files: [results.csv](results.csv) (full precision and extra columns), "
         "[manifest.json](manifest.json), [report.html](report.html)\n\n";
    const std::vector<std::string> cols = display_columns(e.runs);
    const auto marked = best_cells(e.runs, cols);  // experiments/report/report.h
    o << "Key columns first; **bold**: the best (lowest) value of that column among the runs of the same "
         "BRDF.\n\n";
    o << "|";
    for (const auto& c : cols) o << " " << c << " |";
    o << "\n|";
    for (size_t i = 0; i < cols.size(); ++i) o << "---|";
    o << "\n";
    for (const auto& r : e.runs) {
      o << "|";
      for (const auto& c : cols) {
        auto it = r.row.find(c);
        const std::string cell = it == r.row.end() ? "" : it->second;
        std::string shown = md_text(c == "run_id" ? cell : format_short(cell));
        if (c == "run_id" && r.status == "ok") shown = "[" + shown + "](runs/" + url_path(cell) + "/run.json)";
        if (!cell.empty() && marked.count({size_t(&r - e.runs.data()), c})) shown = "**" + shown + "**";
        o << " " << shown << " |";
      }
      o << "\n";
    }
    if (!f.plots.empty()) {
      o << "\n## Plots\n\n";
      for (const auto& p : f.plots)
        if (p.size() > 4 && p.substr(p.size() - 4) == ".png") o << "![" << md_text(p) << "](" << url_path(p) << ")\n\n";
    } else if (!f.plots_note.empty()) {
      o << "\nPlots: " << md_text(f.plots_note) << "\n";
    }
  });
}

json run_to_json(const RunEntry& r) {
  json j = {{"run_id", r.run_id}, {"status", r.status}, {"shard", r.shard},
            {"row", r.row},       {"files", r.files}};
  for (const char* k : {"brdf", "sampling", "method", "seeds", "terms", "size_choice", "notes", "error",
                        "samples_description", "wall_seconds"})
    if (r.record.contains(k)) j[k] = r.record[k];
  return j;
}

}  // namespace

// ------------------------------------------------------------------ all outputs

OutputFiles write_experiment_outputs(const ExperimentOutput& e, std::ostream* log) {
  OutputFiles f;
  const fs::path dir(e.dir);
  fs::create_directories(dir);
  write_file_atomic((dir / "config.toml").string(), [&](std::ostream& o) { o << e.config_text; });
  f.results_csv = (dir / "results.csv").string();
  std::vector<Row> rows;
  for (const auto& r : e.runs) rows.push_back(r.row);
  write_results_csv(f.results_csv, rows);

  // Plots. plots.log is kept only when the script fails (plot_step.h).
  std::error_code log_ec;
  fs::remove(dir / "plots.log", log_ec);
  if (!e.plots) {
    f.plots_note = "not requested (plots = false or --no-plots)";
  } else if (e.runs.empty()) {
    f.plots_note = "no runs";
  } else {
    std::string why;
    const std::string py = find_python(&why);
    const std::string script = plot_script_path();
    if (py.empty()) {
      f.plots_note = why;
    } else if (!fs::exists(script)) {
      f.plots_note = "plot script not found at " + script + " (set BRDF_FACTOR_PLOT_SCRIPT)";
    } else {
      // stdout: the "wrote" lines; stderr (a traceback) to plots.log, and one
      // line of it (the exception) in the note, the error and the tables.
      int st = 0;
      const std::string log_path = (dir / "plots.log").string();
      const std::string cmd = shell_quote(py) + " " + shell_quote(script) + " " + shell_quote(f.results_csv) +
                              " --out " + shell_quote((dir / "plots").string()) + " 2> " + shell_quote(log_path);
      const std::string outp = run_capture(cmd, &st);
      std::error_code ec;
      if (st == 0) fs::remove(log_path, ec);
      if (st != 0) {
        std::string last;  // the last non-empty line of stderr, else of stdout
        for (const std::string& text : {outp, read_text_prefix(log_path)}) {
          std::istringstream ss(text);
          for (std::string line; std::getline(ss, line);)
            if (!trim(line).empty()) last = trim(line);
        }
        for (char& c : last)
          if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
        if (last.size() > 300) last = last.substr(0, 300) + "...";
        const std::string status = WIFEXITED(st)     ? "exit status " + std::to_string(WEXITSTATUS(st))
                                   : WIFSIGNALED(st) ? "killed by signal " + std::to_string(WTERMSIG(st))
                                                     : "status " + std::to_string(st);
        f.plots_note = script + " failed (" + status + ")" + (last.empty() ? "" : ": " + last) +
                       " (its output: plots.log)";
      } else {
        std::istringstream ss(outp);
        std::string line;
        while (std::getline(ss, line)) {
          line = trim(line);
          if (line.rfind("wrote ", 0) == 0) {
            const fs::path p(line.substr(6));
            if (fs::exists(p)) f.plots.push_back("plots/" + p.filename().string());
          }
        }
        if (f.plots.empty()) f.plots_note = "plot_results.py wrote no plot (no usable rows)";
      }
    }
  }
  if (log && !f.plots_note.empty()) *log << "plots: " << f.plots_note << "\n";

  f.results_md = (dir / "results.md").string();
  write_results_md(e, f, f.results_md);

  json m;
  m["format"] = kExperimentFormat;
  m["format_version"] = kExperimentFormatVersion;
  m["created"] = now_iso();
  m["experiment"] = e.experiment;
  m["config"] = {{"path", e.config_path}, {"file", "config.toml"}, {"text", e.config_text},
                 {"defines", e.defines}, {"plan_hash", e.plan_hash}};
  m["versions"] = software_versions();
  m["shard"] = {{"k", e.shard}, {"n", e.shards}};
  m["plan"] = e.plan;
  json runs = json::array();
  for (const auto& r : e.runs) runs.push_back(run_to_json(r));
  m["runs"] = runs;
  m["columns"] = result_columns();
  m["plots"] = f.plots;
  if (!f.plots_note.empty()) m["plots_note"] = f.plots_note;
  if (!e.merged_from.empty()) m["merged_from"] = e.merged_from;
  m["files"] = {"config.toml", "results.csv", "results.md", "manifest.json", "report.html"};
  f.manifest = (dir / "manifest.json").string();
  write_file_atomic(f.manifest, [&](std::ostream& o) { o << m.dump(2) << "\n"; });

  f.report = (dir / "report.html").string();
  write_report_html(e, f, f.report);
  return f;
}

std::string plot_failure(const OutputFiles& f) {
  std::error_code ec;
  if (f.results_md.empty() || !fs::exists(fs::path(f.results_md).parent_path() / "plots.log", ec)) return "";
  return "plots: " + f.plots_note + "; the tables are written: " + f.results_md;
}

ExperimentOutput read_experiment_manifest(const std::string& dir) {
  const std::string path = (fs::path(dir) / "manifest.json").string();
  if (fs::exists(path)) check_regular_file(path, kMaxTextFileBytes, "manifest");
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": not found (is " + dir + " an experiment folder written by `run`?)");
  json m;
  try {
    in >> m;
  } catch (const std::exception& ex) {
    throw std::invalid_argument(path + ": not valid JSON: " + ex.what());
  }
  auto need = [&](const char* k, json::value_t t) -> const json& {
    if (!m.contains(k)) throw std::invalid_argument(path + ": " + k + ": missing");
    if (m[k].type() != t) throw std::invalid_argument(path + ": " + k + ": wrong type");
    return m[k];
  };
  if (m.value("format", "") != kExperimentFormat)
    throw std::invalid_argument(path + ": format: expected \"" + std::string(kExperimentFormat) + "\", found " +
                                (m.contains("format") ? m["format"].dump() : "nothing"));
  if (m.value("format_version", 0) != kExperimentFormatVersion)
    throw std::invalid_argument(path + ": format_version: expected " + std::to_string(kExperimentFormatVersion) +
                                ", found " + (m.contains("format_version") ? m["format_version"].dump() : "nothing"));
  ExperimentOutput e;
  e.dir = dir;
  e.experiment = need("experiment", json::value_t::object);
  const json& c = need("config", json::value_t::object);
  e.config_path = c.value("path", "");
  e.config_text = c.value("text", "");
  e.defines = c.value("defines", std::vector<std::string>{});
  e.plan_hash = c.value("plan_hash", "");
  const json& sh = need("shard", json::value_t::object);
  e.shard = sh.value("k", 1);
  e.shards = sh.value("n", 1);
  e.plan = need("plan", json::value_t::array);
  // Names read from the manifest become paths (runs/<run_id>): plain names only.
  for (size_t i = 0; i < e.plan.size(); ++i) {
    const std::string where = path + ": plan[" + std::to_string(i) + "].run_id";
    const json& p = e.plan[i];
    if (!p.is_object() || !p.contains("run_id") || !p["run_id"].is_string())
      throw std::invalid_argument(where + ": expected a string");
    require_plain_name(p["run_id"].get<std::string>(), where);
  }
  size_t index = 0;
  for (const json& r : need("runs", json::value_t::array)) {
    const std::string where = path + ": runs[" + std::to_string(index++) + "]";
    if (!r.is_object()) throw std::invalid_argument(where + ": expected an object");
    RunEntry re;
    re.run_id = r.value("run_id", "");
    re.status = r.value("status", "");
    re.shard = r.value("shard", 1);
    if (re.run_id.empty()) throw std::invalid_argument(path + ": runs: an entry without run_id");
    require_plain_name(re.run_id, where + ".run_id");
    const json row = r.value("row", json::object());
    for (const auto& [k, v] : row.items())
      re.row[k] = v.is_string() ? v.get<std::string>() : v.dump();
    re.files = r.value("files", std::vector<std::string>{});
    for (const auto& f : re.files) require_path_inside(f, where + ".files", "the experiment folder");
    re.record = r;
    e.runs.push_back(std::move(re));
  }
  return e;
}

}  // namespace bf
