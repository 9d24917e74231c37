// A run's folder (see run_folder.h).
#include "experiments/run_folder.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include "brdfs/safe_path.h"
#include "experiments/cli_util.h"

namespace bf {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::vector<std::string> list_files(const fs::path& exp_dir, const fs::path& run_dir) {
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(run_dir))
    if (e.is_regular_file()) {
      const std::string name = e.path().filename().string();
      if (name == "DONE" || name[0] == '.') continue;
      files.push_back(fs::relative(e.path(), exp_dir).generic_string());
    }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

json run_record(const Plan& plan, const PlannedRun& pr, const SampleSet& samples) {
  const BrdfVariant& b = plan.brdfs[pr.brdf];
  const SamplingVariant& s = plan.samplings[pr.sampling];
  const MethodVariant& m = plan.methods[pr.method];
  json seeds = {{"experiment", plan.experiment.seed}};
  if (s.kind == "stratified") seeds["sampling"] = s.seed;
  if (m.impl->seeded()) seeds["method"] = m.seed;
  return {{"run_id", pr.run_id},
          {"identity", pr.identity},
          {"brdf", {{"label", b.label}, {"eval", b.brdf->to_string()}}},
          {"sampling", s.label},
          {"samples_description", samples.summary()},
          {"method", m.options},
          {"execution", m.execution},
          {"seeds", seeds}};
}

void fill_common_columns(const RunContext& c, const MethodOutcome& out, const Metrics& mt, double seconds,
                         Row& row, std::vector<std::string>& notes, json& rec) {
  const MethodVariant& m = c.method;
  row["samples"] = std::to_string(mt.samples);
  const std::pair<const char*, double> metric_cells[] = {
      {"rel_mse", mt.rel_mse},   {"rel_mae", mt.rel_mae}, {"rel_max", mt.rel_max},  {"lin_rmse", mt.lin_rmse},
      {"lin_mae", mt.lin_mae},   {"lin_max", mt.lin_max}, {"cos_rmse", mt.cos_rmse}};
  for (const auto& [k, v] : metric_cells) {
    row[k] = format_number(v);
    if (row[k].empty()) notes.push_back(std::string(k) + " not finite");
  }
  row["storage_floats"] = std::to_string(out.result->storage_floats());
  row["seconds"] = format_number(std::round(seconds * 1000.0) / 1000.0);
  row["evaluations"] = std::to_string(out.evaluations);
  row["seed"] = m.impl->seeded() ? std::to_string(m.seed) : "";
  row["status"] = "ok";
  if (!out.choice) return;
  const SizeChoice& choice = *out.choice;
  row["tolerance"] = choice.metric + "<=" + format_number(m.tolerance->value);
  row["tolerance_reached"] = choice.reached ? "true" : "false";
  if (!choice.reached)
    notes.push_back("tolerance not reached up to the cap; best tried: " + format_number(choice.error));
  json tried = json::array();
  for (const auto& t : choice.tried) {
    json tj = {{"value", t.value}, {"view_order", t.view_order},
               {"error", std::isfinite(t.error) ? json(t.error) : json()}};
    if (t.texture_size) tj["texture_size"] = t.texture_size;
    tried.push_back(tj);
  }
  rec["size_choice"] = {{"knob", choice.knob.empty() ? "terms" : choice.knob}, {"value", choice.value},
                        {"view_order", choice.view_order}, {"metric", choice.metric},
                        {"error", std::isfinite(choice.error) ? json(choice.error) : json()},
                        {"reached", choice.reached}, {"seconds", choice.seconds}, {"tried", tried}};
  if (choice.texture_size) rec["size_choice"]["texture_size"] = choice.texture_size;
}

std::vector<std::string> finish_run_folder(const fs::path& exp_dir, const fs::path& run_dir, const std::string& run_id,
                                           const Row& row, json& rec) {
  std::vector<std::string> files = list_files(exp_dir, run_dir);
  files.push_back(fs::relative(run_dir / "run.json", exp_dir).generic_string());
  std::sort(files.begin(), files.end());
  rec["row"] = row;
  rec["files"] = files;
  write_file_atomic((run_dir / "run.json").string(), [&](std::ostream& o) { o << rec.dump(2) << "\n"; });
  // The done-marker comes last: a folder without it is an unfinished run.
  write_file_atomic((run_dir / "DONE").string(), [&](std::ostream& o) { o << run_id << "\n"; });
  return files;
}

std::optional<RunEntry> load_done_run(const fs::path& exp_dir, const std::string& run_id) {
  const fs::path run_dir = exp_dir / "runs" / run_id;
  std::error_code ec;
  if (!fs::exists(run_dir / "DONE", ec)) return std::nullopt;
  std::ifstream in(run_dir / "run.json");
  if (!in) return std::nullopt;
  json rec;
  try {
    in >> rec;
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (rec.value("run_id", "") != run_id || !rec.contains("row") || !rec["row"].is_object()) return std::nullopt;
  RunEntry e;
  e.run_id = run_id;
  e.status = "ok";
  for (const auto& [k, v] : rec["row"].items()) e.row[k] = v.is_string() ? v.get<std::string>() : v.dump();
  e.files = rec.value("files", std::vector<std::string>{});
  for (const auto& f : e.files)
    if (!is_path_inside(f) || !fs::exists(exp_dir / f, ec)) return std::nullopt;
  e.record = rec;
  return e;
}

bool incomplete_folder(const fs::path& exp_dir, const std::string& run_id) {
  std::error_code ec;
  return fs::exists(exp_dir / "runs" / run_id, ec);
}

json build_identity(const json& versions) {
  json b = {{"brdf_factor", versions.value("brdf_factor", "")}};
  if (versions.contains("git_commit")) {
    b["git_commit"] = versions["git_commit"];
    b["git_dirty"] = versions.value("git_dirty", false);
  }
  return b;
}

std::string cached_run_commit(const json& record) {
  const auto it = record.find("build");
  if (it == record.end() || !it->is_object()) return "";
  const auto c = it->find("git_commit");
  return c != it->end() && c->is_string() ? c->get<std::string>() : "";
}

}  // namespace bf
