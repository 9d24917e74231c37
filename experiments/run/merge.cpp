// Collating shard folders into one experiment folder (runner.h: merge_experiments).
#include <filesystem>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <stdlib.h>

#include <cerrno>
#include <cstring>

#include "experiments/common/cli_util.h"
#include "experiments/run/file_integrity.h"
#include "experiments/run/outdir_lock.h"
#include "experiments/report/plot_step.h"
#include "experiments/run/run_folder.h"
#include "experiments/run/runner.h"

namespace bf {

namespace fs = std::filesystem;

namespace {

// "" when p is what a shard's folder holds there: a real folder (file =
// false) or a regular file (file = true), neither a link; else why not, naming p.
std::string unsafe_entry(const fs::path& p, bool file = false) {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(p, ec);
  if (file ? st.type() == fs::file_type::regular : st.type() == fs::file_type::directory) return "";
  return p.string() + ": expected " + (file ? "a regular file" : "a folder") + ", found " + describe_file_type(p);
}

// A shard's planned run found done in its manifest: the shard's index and its entry.
using FoundRuns = std::map<std::string, std::pair<size_t, const RunEntry*>>;

// A run folder to copy, checked and verified.
struct Source {
  fs::path dir;            // the shard's runs/<id>
  RunFileHashes files;     // verified: path relative to the shard -> hash
  RunEntry entry;
};

// Refuses an empty list, --out among the shard folders and a linked manifest;
// reads every shard's manifest and checks they are shards of one plan, each
// given once. shard_dir: shard number -> its folder.
std::vector<ExperimentOutput> read_shards(const std::vector<std::string>& dirs, const std::string& out_dir,
                                          std::map<int, std::string>& shard_dir) {
  if (dirs.empty()) throw std::invalid_argument("merge: expected at least one shard folder");
  if (out_dir.empty()) throw std::invalid_argument("merge: --out: expected the folder to write");
  std::error_code ec;
  for (const auto& d : dirs)
    if (fs::exists(out_dir, ec) && fs::exists(d, ec) && fs::equivalent(d, out_dir, ec))
      throw std::invalid_argument("merge: --out " + out_dir + " is one of the shard folders; choose a new folder");
  // Nothing in a shard folder is followed through a link (the folders given are taken as they are).
  for (const auto& d : dirs) {
    const fs::path m = fs::path(d) / "manifest.json";
    if (fs::is_symlink(fs::symlink_status(m, ec)))
      throw std::invalid_argument("merge: " + m.string() + ": expected a regular file, found " +
                                  describe_file_type(m) + "; merge follows no link in a shard folder");
  }
  std::vector<ExperimentOutput> shards;
  for (const auto& d : dirs) shards.push_back(read_experiment_manifest(d));
  const ExperimentOutput& first = shards[0];
  std::vector<std::string> problems;
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
  return shards;
}

// Every planned run exactly once, done; throws naming the missing and the
// duplicated ones (at most 10 of each).
FoundRuns find_planned_runs(const std::vector<std::string>& dirs, const std::vector<ExperimentOutput>& shards,
                            const std::map<int, std::string>& shard_dir) {
  const ExperimentOutput& first = shards[0];
  std::error_code ec;
  FoundRuns found;
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
    if (!fs::exists(fs::symlink_status(fs::path(dirs[it->second.first]) / "runs" / id / "DONE", ec)))
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
  return found;
}

// One planned run's folder checked and verified: regular files only (no link,
// FIFO, device or subfolder, none followed), each listed file's content hash
// as its DONE marker records it. problem: why not, else left empty.
Source verified_source(const std::string& dir, const std::string& id, const RunEntry& entry,
                       std::string& problem) {
  const fs::path shard(dir);
  Source src{shard / "runs" / id, {}, entry};
  problem = unsafe_entry(shard / "runs");
  if (problem.empty()) problem = unsafe_entry(src.dir);
  if (problem.empty()) {
    std::error_code it_ec;
    for (fs::directory_iterator it(src.dir, it_ec), end; !it_ec && it != end && problem.empty(); it.increment(it_ec))
      problem = unsafe_entry(it->path(), /*file=*/true);
    if (problem.empty() && it_ec) problem = src.dir.string() + ": cannot list: " + it_ec.message();
  }
  if (problem.empty()) {
    const auto done = load_done_run(shard, id, &problem, &src.files);
    if (done) {
      // The row and record come from the verified run.json; the manifest's
      // presentation columns (labels of this plan) are kept.
      RunEntry verified = *done;
      for (const char* k : {"sweep", "brdf", "method", "label", "sampling"})
        if (auto it = entry.row.find(k); it != entry.row.end()) verified.row[k] = it->second;
      verified.shard = entry.shard;
      src.entry = std::move(verified);
    } else if (problem.empty()) {
      problem = src.dir.string() + ": has no DONE marker";
    }
  }
  return src;
}

// Every run folder to copy is checked and verified before anything is
// written, and --out (and its runs/) is a folder if it exists; throws naming
// every folder refused (at most 10).
std::vector<Source> verified_sources(const std::vector<std::string>& dirs, const ExperimentOutput& first,
                                     const FoundRuns& found, const fs::path& odir) {
  std::error_code ec;
  std::vector<Source> sources;
  std::vector<std::string> refused;
  for (const auto& p : first.plan) {
    const std::string id = p.value("run_id", "");
    const auto& [si, entry] = found.at(id);
    std::string problem;
    sources.push_back(verified_source(dirs[si], id, *entry, problem));
    if (!problem.empty()) refused.push_back(problem);
  }
  for (const fs::path& p : {odir, odir / "runs"})
    if (fs::exists(fs::symlink_status(p, ec)) && !fs::is_directory(fs::symlink_status(p, ec)))
      refused.push_back(p.string() + ": expected a folder, found " + describe_file_type(p));
  if (!refused.empty()) {
    std::string msg = "merge: " + std::to_string(refused.size()) + " run folder" + (refused.size() > 1 ? "s" : "") +
                      " not merged: ";
    for (size_t i = 0; i < refused.size() && i < 10; ++i) msg += (i ? "; " : "") + refused[i];
    if (refused.size() > 10) msg += "; ...";
    throw std::invalid_argument(msg + " (merge copies the regular files a run lists and follows no link; "
                                      "run that shard again)");
  }
  return sources;
}

// The merged experiment's description: the first shard's plan and config, one shard, in `stage`.
ExperimentOutput merged_output(const ExperimentOutput& first, const std::vector<std::string>& dirs,
                               const fs::path& stage, bool plots) {
  ExperimentOutput o;
  o.dir = stage.string();
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
  return o;
}

// Copies each verified run folder into the stage (each file's hash checked
// again as it is copied) with a new DONE marker, and adds its entry to o and sum.
void copy_runs_into_stage(const std::vector<Source>& sources, const fs::path& stage, ExperimentOutput& o,
                          RunSummary& sum) {
  for (const Source& src : sources) {
    const std::string& id = src.entry.run_id;
    const fs::path dst = stage / "runs" / id;
    fs::create_directories(dst);
    const fs::path shard = src.dir.parent_path().parent_path();
    for (const auto& [rel, recorded] : src.files) {
      const std::string copied = copy_regular_file(shard / rel, stage / rel);
      if (copied != recorded)
        throw std::runtime_error((shard / rel).string() + ": content hash changed while merging (recorded " +
                                 recorded + ", copied " + copied + ")");
    }
    std::vector<std::string> listed;
    for (const auto& [rel, h] : src.files) listed.push_back(rel);
    write_done_marker(dst, done_marker(stage, id, listed));
    o.runs.push_back(src.entry);
    sum.run_ids.push_back(id);
  }
}

// Into place: each run folder, then the tables (report last).
void move_stage_into_place(const fs::path& stage, const fs::path& odir, const std::vector<std::string>& run_ids) {
  std::error_code ec;
  fs::create_directories(odir / "runs");
  for (const auto& id : run_ids) {
    fs::remove_all(odir / "runs" / id);
    fs::rename(stage / "runs" / id, odir / "runs" / id);
  }
  if (fs::exists(stage / "plots")) {
    fs::remove_all(odir / "plots");
    fs::rename(stage / "plots", odir / "plots");
  }
  // plots.log exists only when the plot step failed (plot_step.h): an older one goes.
  fs::remove(odir / "plots.log", ec);
  for (const char* f : {"config.toml", "results.csv", "results.md", "manifest.json", "plots.log", "report.html"})
    if (fs::exists(stage / f)) fs::rename(stage / f, odir / f);
}

}  // namespace

RunSummary merge_experiments(const std::vector<std::string>& dirs, const std::string& out_dir, bool quiet,
                             bool plots, std::ostream& out, std::ostream& err) {
  std::map<int, std::string> shard_dir;
  const std::vector<ExperimentOutput> shards = read_shards(dirs, out_dir, shard_dir);
  const ExperimentOutput& first = shards[0];
  const FoundRuns found = find_planned_runs(dirs, shards, shard_dir);
  const fs::path odir = fs::path(out_dir).lexically_normal();
  const std::vector<Source> sources = verified_sources(dirs, first, found, odir);

  // The merged folder is built next to --out and moved into it at the end,
  // so an error leaves --out as it was (or absent).
  std::error_code ec;
  const bool out_existed = fs::exists(fs::symlink_status(odir, ec));
  const OutdirLock lock(out_dir, "merge");
  fs::path parent = odir.parent_path();
  if (parent.empty()) parent = ".";
  const std::string name = odir.filename().empty() ? std::string("merged") : odir.filename().string();
  std::string pattern = (parent / ("." + name + ".merge-XXXXXX")).string();
  if (!::mkdtemp(pattern.data()))
    throw std::runtime_error("merge: " + parent.string() + ": cannot create a staging folder: " + std::strerror(errno));
  const fs::path stage(pattern);
  auto clean_up = [&] {
    std::error_code e2;
    fs::remove_all(stage, e2);
    if (!out_existed) {
      fs::remove(odir / OutdirLock::kFileName, e2);
      fs::remove(odir, e2);  // only if empty
    }
  };

  ExperimentOutput o = merged_output(first, dirs, stage, plots);
  RunSummary sum;
  sum.out_dir = out_dir;
  sum.planned = first.plan.size();
  try {
    copy_runs_into_stage(sources, stage, o, sum);
    sum.in_shard = o.runs.size();
    sum.cached = o.runs.size();
    if (!quiet)
      err << "merge: " << o.runs.size() << " runs from " << dirs.size() << " shard folders -> " << out_dir << "\n";
    sum.files = write_experiment_outputs(o, quiet ? nullptr : &err);
    move_stage_into_place(stage, odir, sum.run_ids);
  } catch (...) {
    clean_up();
    throw;
  }
  fs::remove_all(stage, ec);
  sum.files.results_csv = (odir / "results.csv").string();
  sum.files.results_md = (odir / "results.md").string();
  sum.files.manifest = (odir / "manifest.json").string();
  sum.files.report = (odir / "report.html").string();
  print_output_paths(out, sum.files);
  if (const std::string p = plot_failure(sum.files); !p.empty()) throw std::runtime_error(p);  // tables written
  return sum;
}

}  // namespace bf
