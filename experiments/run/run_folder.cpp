// A run's folder (see run_folder.h).
#include "experiments/run/run_folder.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include "brdfs/file_check.h"
#include "brdfs/safe_path.h"
#include "experiments/common/cli_util.h"
#include "experiments/run/file_integrity.h"

namespace bf {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The DONE marker's hash function (file_integrity.h).
constexpr const char* kDoneHash = "fnv1a64";

std::vector<std::string> list_files(const fs::path& exp_dir, const fs::path& run_dir) {
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(run_dir))
    if (fs::is_regular_file(e.symlink_status())) {
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

std::vector<std::string> write_run_record(const fs::path& exp_dir, const fs::path& run_dir, const std::string& run_id,
                                          const Row& row, json& rec) {
  (void)run_id;
  std::vector<std::string> files = list_files(exp_dir, run_dir);
  files.push_back(fs::relative(run_dir / "run.json", exp_dir).generic_string());
  std::sort(files.begin(), files.end());
  rec["row"] = row;
  rec["files"] = files;
  write_file_atomic((run_dir / "run.json").string(), [&](std::ostream& o) { o << rec.dump(2) << "\n"; });
  return files;
}

std::string done_marker(const fs::path& exp_dir, const std::string& run_id, const std::vector<std::string>& files) {
  json hashes = json::object();
  for (const auto& f : files) hashes[f] = regular_file_hash(exp_dir / f);
  return json{{"run_id", run_id}, {"hash", kDoneHash}, {"files", hashes}}.dump(1) + "\n";
}

void write_done_marker(const fs::path& run_dir, const std::string& marker) {
  // The done-marker comes last: a folder without it is an unfinished run.
  write_file_atomic((run_dir / "DONE").string(), [&](std::ostream& o) { o << marker; });
}

std::optional<RunEntry> load_done_run(const fs::path& exp_dir, const std::string& run_id, std::string* problem,
                                      RunFileHashes* hashes) {
  const fs::path run_dir = exp_dir / "runs" / run_id;
  const fs::path done_path = run_dir / "DONE";
  std::string why_not;
  if (!problem) problem = &why_not;
  problem->clear();
  auto refuse = [&](const fs::path& p, const std::string& what) -> std::optional<RunEntry> {
    *problem = p.string() + ": " + what;
    return std::nullopt;
  };
  std::error_code ec;
  const fs::file_status done_st = fs::symlink_status(done_path, ec);
  if (done_st.type() == fs::file_type::not_found) return std::nullopt;  // not finished
  for (const fs::path& p : {exp_dir / "runs", run_dir})
    if (!fs::is_directory(fs::symlink_status(p, ec)))
      return refuse(p, "expected a folder, found " + describe_file_type(p));
  if (done_st.type() != fs::file_type::regular)
    return refuse(done_path, "expected a regular file, found " + describe_file_type(done_path));

  // The marker: the run id and a content hash per listed file.
  json done;
  try {
    done = json::parse(read_regular_file(done_path.string(), kMaxTextFileBytes, "DONE marker"));
  } catch (const std::exception&) {
    return refuse(done_path, "not a DONE marker with content hashes (an older format, or damaged)");
  }
  if (!done.is_object() || done.value("run_id", json()) != json(run_id) || done.value("hash", json()) != kDoneHash ||
      !done.contains("files") || !done["files"].is_object())
    return refuse(done_path, "expected {\"run_id\": \"" + run_id + "\", \"hash\": \"" + kDoneHash +
                                 "\", \"files\": {...}}, found another content");
  const std::string prefix = "runs/" + run_id + "/";
  RunFileHashes listed;
  for (const auto& [f, h] : done["files"].items()) {
    if (!h.is_string() || f.rfind(prefix, 0) != 0 || !is_plain_name(f.substr(prefix.size())))
      return refuse(done_path, "files: expected names inside " + prefix + " with their hashes, found \"" + f + "\"");
    listed.emplace_back(f, h.get<std::string>());
  }
  for (const auto& [f, recorded] : listed) {
    const fs::path p = exp_dir / f;
    const fs::file_status st = fs::symlink_status(p, ec);
    if (st.type() != fs::file_type::regular)
      return refuse(p, "listed in DONE, expected a regular file, found " + describe_file_type(p));
    std::string actual;
    try {
      actual = regular_file_hash(p);
    } catch (const std::exception& e) {
      *problem = e.what();
      return std::nullopt;
    }
    if (actual != recorded)
      return refuse(p, "content hash mismatch (recorded in DONE " + recorded + ", computed " + actual + ")");
  }

  // The record, now verified.
  const fs::path rec_path = run_dir / "run.json";
  if (!done["files"].contains(prefix + "run.json")) return refuse(done_path, "files: run.json is not listed");
  json rec;
  try {
    rec = json::parse(read_regular_file(rec_path.string(), kMaxTextFileBytes, "run record"));
  } catch (const std::exception& e) {
    return refuse(rec_path, std::string("not valid JSON: ") + e.what());
  }
  if (!rec.is_object() || rec.value("run_id", json()) != json(run_id) || !rec.contains("row") || !rec["row"].is_object())
    return refuse(rec_path, "expected a run record with run_id \"" + run_id + "\" and a row");
  RunEntry e;
  e.run_id = run_id;
  e.status = "ok";
  for (const auto& [k, v] : rec["row"].items()) e.row[k] = v.is_string() ? v.get<std::string>() : v.dump();
  try {
    e.files = rec.value("files", std::vector<std::string>{});
  } catch (const std::exception&) {
    return refuse(rec_path, "files: expected a list of names");
  }
  std::vector<std::string> in_done;
  for (const auto& [f, h] : listed) in_done.push_back(f);
  std::vector<std::string> in_rec = e.files;
  std::sort(in_rec.begin(), in_rec.end());
  std::sort(in_done.begin(), in_done.end());
  if (in_rec != in_done) return refuse(rec_path, "files: the list differs from the DONE marker's");
  e.record = rec;
  if (hashes) *hashes = std::move(listed);
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
