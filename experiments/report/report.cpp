// report.html (see report.h).
#include "experiments/report/report.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <regex>
#include <sstream>

#include "experiments/common/cli_util.h"
#include "experiments/report/escape.h"
#include "experiments/report/viewer.h"
#include "factor/export.h"

namespace bf {

namespace fs = std::filesystem;

namespace {

// Every string of user origin on the page goes through one of these
// (escape.h): HTML text and attribute values, relative URLs.
std::string esc(const std::string& s) { return html_text(s); }
std::string url(const std::string& rel) { return url_path(rel); }

const char* kStyle = R"(
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;margin:2em;color:#222;max-width:1400px}
h1{font-size:1.6em}h2{font-size:1.25em;margin-top:2em;border-bottom:1px solid #ddd}
table{border-collapse:collapse;font-size:0.82em}td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}
th{background:#f0f0f0;position:sticky;top:0}td.t{text-align:left}tr.failed td{background:#fde8e8}
tr.flagged td{background:#fff3e0}td.best,span.best{font-weight:bold;background:#dff3df}.tablewrap{overflow-x:auto;max-width:100%}p.note{font-size:0.85em;color:#555}
.plots{display:grid;grid-template-columns:repeat(auto-fill,minmax(min(100%,440px),1fr));gap:0.8em}
.plots figure{margin:0}.plots img{width:100%;border:1px solid #ddd}.plots figcaption{font-size:0.8em;color:#555}
details.notes summary{cursor:pointer;color:#555}details.notes{max-width:40em;white-space:normal}
@media (max-width:700px){body{margin:0.6em}#viewer canvas{max-width:100%;height:auto!important}}
.run{border:1px solid #ddd;border-radius:6px;padding:0.6em 1em;margin:1em 0}
.run img.sphere{max-width:100%;image-rendering:pixelated}.run img.tex{height:96px;margin-right:4px;image-rendering:pixelated}
.files a{margin-right:0.8em;font-size:0.85em}
.texbar{font-size:0.75em;color:#555;display:inline-block;width:240px;vertical-align:top}
.texbar .ramp{display:block;height:10px;background:linear-gradient(to right,#000,rgb(26,38,217),rgb(230,26,51),rgb(255,217,26),#fff)}
.texbar span:not(.ramp){display:inline-block;width:33.3%;text-align:center}.texbar span:nth-child(2){text-align:left}
.texbar span:nth-child(4){text-align:right}
.vrow{display:flex;flex-wrap:wrap;gap:1em;align-items:flex-start}.vrow figure{margin:0}.vrow figcaption{max-width:420px}
#viewer canvas.vplot{max-width:100%}#viewer canvas.vcmp{width:200px;height:200px;max-width:40vw;max-height:40vw}
.vlist label{display:block;font-size:0.9em}
#viewer canvas#v-orig,#viewer canvas#v-approx,#viewer canvas#v-diff{width:256px;height:256px;max-width:28vw;max-height:28vw;cursor:crosshair}
#viewer canvas#v-slice-orig,#viewer canvas#v-slice-approx{width:180px;height:180px;image-rendering:pixelated}code{background:#f6f6f6;padding:0 3px}
pre{background:#f6f6f6;padding:0.8em;overflow:auto;font-size:0.85em}
)";

bool exists_in(const std::string& dir, const std::string& rel) {
  std::error_code ec;
  return fs::exists(fs::path(dir) / rel, ec);
}

}  // namespace

std::vector<std::string> key_columns_first(const std::vector<std::string>& cols) {
  static const std::vector<std::string> key = {"brdf",          "method",  "label",      "rel_mse",
                                               "cos_rmse",      "shade_rmse", "val_rel_mse", "val_cos_rmse",
                                               "val_max_ratio", "holdout_rel_mse", "flag", "storage_floats",
                                               "seconds",       "evaluations"};
  std::vector<std::string> out;
  for (const auto& k : key)
    if (std::find(cols.begin(), cols.end(), k) != cols.end()) out.push_back(k);
  for (const auto& c : cols)
    if (std::find(out.begin(), out.end(), c) == out.end()) out.push_back(c);
  return out;
}

bool is_marked_column(const std::string& c) {
  static const std::set<std::string> m = {"rel_mse", "rel_mae", "rel_max", "lin_rmse", "lin_mae", "lin_max",
                                          "cos_rmse", "shade_rmse", "val_rel_mse", "val_cos_rmse", "val_max_ratio",
                                          "holdout_rel_mse", "holdout_cos_rmse", "storage_floats", "seconds"};
  return m.count(c) > 0;
}

std::set<std::pair<size_t, std::string>> best_cells(const std::vector<RunEntry>& runs,
                                                    const std::vector<std::string>& cols) {
  std::set<std::pair<size_t, std::string>> out;
  for (const auto& c : cols) {
    if (!is_marked_column(c)) continue;
    // Per BRDF: the smallest value and every run holding it.
    std::map<std::string, std::vector<std::pair<double, size_t>>> by_brdf;
    for (size_t i = 0; i < runs.size(); ++i) {
      if (runs[i].status != "ok") continue;
      auto it = runs[i].row.find(c);
      auto b = runs[i].row.find("brdf");
      if (it == runs[i].row.end() || it->second.empty() || b == runs[i].row.end()) continue;
      char* end = nullptr;
      const double v = std::strtod(it->second.c_str(), &end);
      if (end == it->second.c_str() || *end != '\0' || !std::isfinite(v)) continue;
      by_brdf[b->second].emplace_back(v, i);
    }
    for (const auto& [brdf, vals] : by_brdf) {
      if (vals.size() < 2) continue;
      double best = vals[0].first;
      for (const auto& [v, i] : vals) best = std::min(best, v);
      for (const auto& [v, i] : vals)
        if (v == best) out.emplace(i, c);
    }
  }
  return out;
}

std::vector<std::string> html_links(const std::string& html) {
  std::vector<std::string> out;
  static const std::regex re(R"re((?:href|src)\s*=\s*"([^"]*)")re");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), re); it != std::sregex_iterator(); ++it)
    out.push_back((*it)[1].str());
  return out;
}

namespace {

// A notes cell folded: its first sentence (up to 60 characters) as the
// summary, the whole text inside, so a long note does not make its row tall.
std::string notes_details(const std::string& notes) {
  std::string head = notes.substr(0, std::min(notes.find(". "), notes.size()));
  if (head.size() > 60) {
    size_t cut = 57;  // not inside a UTF-8 sequence
    while (cut > 0 && (static_cast<unsigned char>(head[cut]) & 0xC0) == 0x80) --cut;
    head = head.substr(0, cut) + "...";
  }
  return "<details class=\"notes\"><summary>" + esc(head) + "</summary>" + esc(notes) + "</details>";
}

// The results table: key columns first, best values per BRDF marked,
// failed and flagged rows shaded.
void results_table(const ExperimentOutput& e, std::ostringstream& h) {
  h << "<h2>Results</h2>\n<p class=\"note\">Key columns first. <span class=\"best\">Green bold</span>: "
       "the best (lowest) value of that column among the runs of the same BRDF. Orange rows are flagged "
       "(validation error far above the training error, or values far above the BRDF's peak): the reason "
       "is in notes.</p>\n"
       "<div class=\"tablewrap\"><table><tr>";
  const std::vector<std::string> cols = display_columns(e.runs);
  const auto marked = best_cells(e.runs, cols);
  for (const auto& c : cols) h << "<th>" << esc(c) << "</th>";
  h << "</tr>\n";
  for (const auto& r : e.runs) {
    const auto fl = r.row.find("flag");
    const bool flagged = fl != r.row.end() && !fl->second.empty();
    h << "<tr" << (r.status != "ok" ? " class=\"failed\"" : flagged ? " class=\"flagged\" title=\"flagged: see notes\"" : "")
      << ">";
    for (const auto& c : cols) {
      auto it = r.row.find(c);
      const std::string cell = it == r.row.end() ? "" : it->second;
      const bool text = c == "run_id" || c == "brdf" || c == "method" || c == "label" || c == "parameterization" ||
                        c == "sampling" || c == "notes" || c == "reciprocity" || c == "sweep" ||
                        c == "tolerance" || c == "flag" || c == "search_strategy" ||
                        c == "term_parameterizations";
      const bool best = marked.count({size_t(&r - e.runs.data()), c}) > 0;
      h << "<td" << (text ? " class=\"t\"" : best ? " class=\"best\" title=\"best " + esc(c) + " of this BRDF\"" : "")
        << ">";
      if (c == "run_id") h << "<a href=\"#run-" << esc(cell) << "\">" << esc(cell) << "</a>";
      else if (c == "notes" && !cell.empty()) h << notes_details(cell);
      else h << esc(text ? cell : format_short(cell));
      h << "</td>";
    }
    h << "</tr>\n";
  }
  h << "</table></div>\n";

}

}  // namespace

void write_report_html(const ExperimentOutput& e, const OutputFiles& f, const std::string& path) {
  const std::string dir = fs::path(path).parent_path().string();
  const std::string name = e.experiment.value("name", "experiment");
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" << esc(name)
    << " - brdf-factor</title>\n<style>" << kStyle << "</style></head><body>\n";
  h << "<h1>Experiment " << esc(name) << "</h1>\n";
  if (!e.experiment.value("description", "").empty())
    h << "<p>" << esc(e.experiment.value("description", "")) << "</p>\n";
  size_t failed = 0;
  for (const auto& r : e.runs) failed += r.status != "ok";
  h << "<p>" << e.runs.size() << " runs";
  if (e.shards > 1) h << " (shard " << e.shard << "/" << e.shards << " of " << e.plan.size() << ")";
  if (!e.merged_from.empty()) h << " (merged from " << e.merged_from.size() << " shard folders)";
  if (failed) h << ", <b>" << failed << " failed</b>";
  h << ". Config <code>" << esc(e.config_path) << "</code>";
  for (const auto& d : e.defines) h << " <code>-D " << esc(d) << "</code>";
  h << ".</p>\n<p class=\"files\">";
  for (const char* file : {"results.csv", "results.md", "manifest.json", "config.toml", "plots.log"})
    if (exists_in(dir, file)) h << "<a href=\"" << url(file) << "\">" << file << "</a>";
  h << "</p>\n";

  results_table(e, h);

  // Plots.
  h << "<h2>Plots</h2>\n";
  if (f.plots.empty()) h << "<p>No plots: " << esc(f.plots_note) << "</p>\n";
  else {
    h << "<div class=\"plots\">";
    for (const auto& p : f.plots)
      if (exists_in(dir, p)) {
        const bool img = p.size() > 4 && (p.substr(p.size() - 4) == ".png" || p.substr(p.size() - 4) == ".svg");
        if (img)
          h << "<figure><a href=\"" << url(p) << "\"><img src=\"" << url(p) << "\" alt=\"" << esc(p)
            << "\"></a><figcaption>" << esc(fs::path(p).filename().string()) << "</figcaption></figure>";
        else h << "<a href=\"" << url(p) << "\">" << esc(p) << "</a> ";
      }
    h << "</div>\n";
  }

  // The WebGL2 viewer (experiments/report/viewer.h), when some run wrote its data.
  {
    std::vector<ViewerRun> viewer_runs;
    for (const auto& r : e.runs)
      if (r.status == "ok" && exists_in(dir, "runs/" + r.run_id + "/viewer.js")) {
        auto cell = [&](const char* c) {
          auto it = r.row.find(c);
          return it == r.row.end() ? std::string() : it->second;
        };
        viewer_runs.push_back({r.run_id, "runs/" + r.run_id + "/viewer.js",
                               cell("brdf") + " | " + cell("label") + " " + cell("sweep")});
      }
    if (!viewer_runs.empty()) h << viewer_section(viewer_runs);
  }

  // Runs.
  h << "<h2>Runs</h2>\n<p>Each picture: a unit sphere lit by a point light, rendered with the original BRDF "
       "(left), the approximation (middle) and |difference| as a heat map (right; black = 0, white = 25% of the "
       "original's display white).</p>\n";
  for (const auto& r : e.runs) {
    auto cell = [&](const char* c) {
      auto it = r.row.find(c);
      return it == r.row.end() ? std::string() : it->second;
    };
    h << "<div class=\"run\" id=\"run-" << esc(r.run_id) << "\"><h3>" << esc(r.run_id) << ": "
      << esc(cell("brdf")) << " &middot; " << esc(cell("label")) << " " << esc(cell("sweep")) << " &middot; "
      << esc(cell("sampling"))
      << "</h3>\n";
    h << "<p>rel_mse " << esc(format_short(cell("rel_mse"))) << ", lin_rmse " << esc(format_short(cell("lin_rmse")))
      << ", cos_rmse " << esc(format_short(cell("cos_rmse"))) << ", " << esc(cell("storage_floats"))
      << " floats, " << esc(format_short(cell("seconds"))) << " s";
    h << "</p>\n";
    if (!cell("notes").empty()) h << notes_details(cell("notes")) << "\n";
    std::vector<std::string> pictures, textures, others;
    for (const auto& file : r.files) {
      if (!exists_in(dir, file)) continue;
      const std::string base = fs::path(file).filename().string();
      if (base == "sphere.png") pictures.push_back(file);
      else if (base.size() > 4 && base.substr(base.size() - 4) == ".png") textures.push_back(file);
      else others.push_back(file);
    }
    for (const auto& p : pictures)
      h << "<img class=\"sphere\" loading=\"lazy\" src=\"" << url(p) << "\" alt=\"sphere " << esc(r.run_id)
        << "\"><br>\n";
    for (const auto& p : textures)
      h << "<a href=\"" << url(p) << "\"><img class=\"tex\" loading=\"lazy\" src=\"" << url(p) << "\" alt=\""
        << esc(fs::path(p).filename().string()) << "\"></a>";
    // The previews' colour map (factor/export.h): one fixed log range for all.
    if (!textures.empty())
      h << "<div class=\"texbar\"><span class=\"ramp\"></span><span>10<sup>" << kPreviewLog10Min
        << "</sup></span><span>1</span><span>10<sup>" << kPreviewLog10Max
        << "</sup></span><br>factor value (mean RGB), log scale, the same for every texture; grey: outside "
           "the projection's disk</div>\n";
    h << "<p class=\"files\">";
    for (const auto& file : r.files)
      if (exists_in(dir, file))
        h << "<a href=\"" << url(file) << "\">" << esc(fs::path(file).filename().string()) << "</a>";
    h << "</p></div>\n";
  }
  h << "<h2>Config</h2>\n<pre>" << esc(e.config_text) << "</pre>\n</body></html>\n";
  // Unchanged inputs give the same page: keep the file (and its mtime) then.
  write_file_if_changed(path, [&](std::ostream& o) { o << h.str(); });
}

}  // namespace bf
