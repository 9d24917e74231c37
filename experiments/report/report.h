// report.html: one page (inline style, no network) with the results table,
// the plots, the WebGL2 viewer (its inline script loads runs/<id>/viewer.js,
// viewer.h), each run's sphere picture and factor previews, and a link to
// every file of the experiment folder. Images, links and the viewer's data
// are relative paths inside the folder, so the folder can be moved or
// archived as a whole. Text of user origin is escaped for its context
// (escape.h): HTML text, or JSON inside the script.
#pragma once

#include <set>
#include <string>
#include <utility>
#include <vector>

#include "experiments/report/outputs.h"

namespace bf {

// Writes DIR/report.html atomically. Only files that exist are linked.
void write_report_html(const ExperimentOutput& e, const OutputFiles& files, const std::string& path);

// Every href and src attribute value of an HTML page, in order (tests use it
// to check that all of them resolve).
std::vector<std::string> html_links(const std::string& html);

// The table columns reordered for people: the columns that answer "how good,
// at what storage and time" first (brdf, method, label, rel_mse, cos_rmse,
// shade_rmse, storage_floats, seconds, evaluations), then the rest in their
// given order (run_id after the errors, before the extras).
std::vector<std::string> key_columns_first(const std::vector<std::string>& cols);

// Columns where lower is better and the best value per BRDF is marked: every
// error column (rel_*, lin_*, cos_rmse, shade_rmse) and storage_floats and
// seconds.
bool is_marked_column(const std::string& col);

// The cells holding the best (smallest) value of each marked column among the
// finished runs of the same BRDF, as (run index, column); ties are all marked.
// Only columns with at least two runs of that BRDF holding a value take part.
std::set<std::pair<size_t, std::string>> best_cells(const std::vector<RunEntry>& runs,
                                                    const std::vector<std::string>& cols);

}  // namespace bf
