// Collating shard folders into one experiment folder (runner.h: merge_experiments).
#include <filesystem>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "experiments/cli_util.h"
#include "experiments/outdir_lock.h"
#include "experiments/plot_step.h"
#include "experiments/runner.h"

namespace bf {

namespace fs = std::filesystem;

RunSummary merge_experiments(const std::vector<std::string>& dirs, const std::string& out_dir, bool quiet,
                             bool plots, std::ostream& out, std::ostream& err) {
  if (dirs.empty()) throw std::invalid_argument("merge: expected at least one shard folder");
  if (out_dir.empty()) throw std::invalid_argument("merge: --out: expected the folder to write");
  std::error_code ec;
  for (const auto& d : dirs)
    if (fs::exists(out_dir, ec) && fs::exists(d, ec) && fs::equivalent(d, out_dir, ec))
      throw std::invalid_argument("merge: --out " + out_dir + " is one of the shard folders; choose a new folder");
  std::vector<ExperimentOutput> shards;
  for (const auto& d : dirs) shards.push_back(read_experiment_manifest(d));
  const ExperimentOutput& first = shards[0];
  std::vector<std::string> problems;
  std::map<int, std::string> shard_dir;
  for (size_t i = 0; i < shards.size(); ++i) {
    const auto& s = shards[i];
    if (s.plan_hash != first.plan_hash)
      problems.push_back(dirs[i] + ": plan " + s.plan_hash + " differs from " + dirs[0] + "'s " + first.plan_hash +
                         " (shards of different configs or overrides)");
    if (s.shards != first.shards)
      problems.push_back(dirs[i] + ": shard count " + std::to_string(s.shards) + " differs from " + dirs[0] +
                         "'s " + std::to_string(first.shards));
    auto [it, fresh] = shard_dir.emplace(s.shard, dirs[i]);
    if (!fresh)
      problems.push_back("shard " + std::to_string(s.shard) + "/" + std::to_string(s.shards) +
                         " given twice: " + it->second + " and " + dirs[i]);
  }
  if (!problems.empty()) throw std::invalid_argument("merge: " + join(problems, "; "));

  // Every planned run exactly once, done.
  std::map<std::string, std::pair<size_t, const RunEntry*>> found;
  std::vector<std::string> duplicates, missing;
  for (size_t i = 0; i < shards.size(); ++i)
    for (const auto& r : shards[i].runs) {
      if (r.status != "ok") continue;
      auto [it, fresh] = found.emplace(r.run_id, std::make_pair(i, &r));
      if (!fresh) duplicates.push_back(r.run_id + " (in " + dirs[it->second.first] + " and " + dirs[i] + ")");
    }
  for (const auto& p : first.plan) {
    const std::string id = p.value("run_id", "");
    auto it = found.find(id);
    if (it == found.end()) {
      const int k = p.value("shard", 1);
      missing.push_back(id + " (shard " + std::to_string(k) + (shard_dir.count(k) ? ", failed or unfinished there" :
                                                               ", no folder given") + ")");
      continue;
    }
    if (!fs::exists(fs::path(dirs[it->second.first]) / "runs" / id / "DONE", ec))
      missing.push_back(id + " (" + dirs[it->second.first] + "/runs/" + id + " has no DONE marker)");
  }
  std::set<std::string> planned;
  for (const auto& p : first.plan) planned.insert(p.value("run_id", ""));
  for (const auto& [id, where] : found)
    if (!planned.count(id)) duplicates.push_back(id + " (in " + dirs[where.first] + " but not in the plan)");
  if (!duplicates.empty() || !missing.empty()) {
    std::string msg = "merge: ";
    if (!missing.empty()) {
      msg += std::to_string(missing.size()) + " of " + std::to_string(first.plan.size()) + " runs missing: ";
      for (size_t i = 0; i < missing.size() && i < 10; ++i) msg += (i ? ", " : "") + missing[i];
      if (missing.size() > 10) msg += ", ...";
    }
    if (!duplicates.empty()) {
      msg += std::string(missing.empty() ? "" : "; ") + std::to_string(duplicates.size()) + " duplicated: ";
      for (size_t i = 0; i < duplicates.size() && i < 10; ++i) msg += (i ? ", " : "") + duplicates[i];
    }
    throw std::invalid_argument(msg);
  }

  // Copy the run folders and write the merged folder.
  const fs::path odir(out_dir);
  const OutdirLock lock(out_dir, "merge");
  fs::create_directories(odir / "runs");
  ExperimentOutput o;
  o.dir = out_dir;
  o.experiment = first.experiment;
  o.config_path = first.config_path;
  o.config_text = first.config_text;
  o.defines = first.defines;
  o.plan_hash = first.plan_hash;
  o.shard = 1;
  o.shards = 1;
  o.plan = first.plan;
  o.plots = plots;
  o.merged_from = dirs;
  RunSummary sum;
  sum.out_dir = out_dir;
  sum.planned = first.plan.size();
  for (const auto& p : first.plan) {
    const std::string id = p.value("run_id", "");
    const auto& [si, entry] = found.at(id);
    const fs::path src = fs::path(dirs[si]) / "runs" / id, dst = odir / "runs" / id;
    if (!(fs::exists(dst, ec) && fs::equivalent(src, dst, ec))) {
      fs::remove_all(dst);
      fs::copy(src, dst, fs::copy_options::recursive);
    }
    o.runs.push_back(*entry);
    sum.run_ids.push_back(id);
  }
  sum.in_shard = o.runs.size();
  sum.cached = o.runs.size();
  if (!quiet) err << "merge: " << o.runs.size() << " runs from " << dirs.size() << " shard folders -> " << out_dir << "\n";
  sum.files = write_experiment_outputs(o, quiet ? nullptr : &err);
  print_output_paths(out, sum.files);
  if (const std::string p = plot_failure(sum.files); !p.empty()) throw std::runtime_error(p);  // tables written
  return sum;
}

}  // namespace bf
