// report.html: one self-contained page (inline style, no scripts, no network)
// with the results table, the plots, each run's sphere picture and factor
// previews, and a link to every file of the experiment folder. Images and
// links are relative paths inside the folder, so the folder can be moved or
// archived as a whole.
#pragma once

#include <string>

#include "experiments/outputs.h"

namespace bf {

// Writes DIR/report.html atomically. Only files that exist are linked.
void write_report_html(const ExperimentOutput& e, const OutputFiles& files, const std::string& path);

// Every href and src attribute value of an HTML page, in order (tests use it
// to check that all of them resolve).
std::vector<std::string> html_links(const std::string& html);

}  // namespace bf
