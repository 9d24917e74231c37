// Strings of user origin in every output context (docs/robustness.md,
// "Strings by context"): BRDF names, labels, notes, the description and
// sweep values holding markdown, HTML, script and mathtext syntax reach
// results.md (one line per row, the right column count, no raw HTML),
// report.html (none of them raw, the embedded JSON parses back to the same
// strings, the viewer still loads in headless Chromium) and the plots
// (matplotlib draws them as plain text); a failing plot step is an error.
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <nlohmann/json.hpp>

#include "experiments/report/escape.h"
#include "experiments/report/outputs.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {

// Hostile strings: markdown block and inline syntax, HTML that would open a
// comment or a script, entities, quotes, line breaks of every kind, control
// characters, mathtext.
const std::vector<std::string>& hostile() {
  static const std::vector<std::string> h = {
      "a\n# heading",
      "<b>x</b>",
      "a|b",
      "`code`",
      "x\r\ny\rz\tw",
      "back\\|slash\\",
      "<!--<script>",
      "</script><script>alert(1)</script>",
      "X&Y &amp; X<Y X>Y X\"Y X'Y",
      "*em* _u_ [l](http://x) ~~s~~ ![i](j) <http://auto>",
      "- item",
      "1. item",
      "    indented",
      "\x1b[31mred\x7f",
      "line\xE2\x80\xA8sep\xE2\x80\xA9para",
      "$x$ $ \\alpha ^ % { } _",
      "=== ---",
  };
  return h;
}

RunEntry hostile_run(size_t i) {
  const auto& h = hostile();
  RunEntry r;
  r.run_id = "run" + std::to_string(i);
  r.status = "ok";
  r.row["run_id"] = r.run_id;
  r.row["brdf"] = h[i % h.size()];
  r.row["label"] = h[(i + 1) % h.size()];
  r.row["method"] = "mccool";
  r.row["notes"] = h[(i + 2) % h.size()];
  r.row["sweep"] = "label=" + h[(i + 3) % h.size()];
  r.row["parameterization"] = "wiwo";
  r.row["terms"] = "1";
  r.row["rel_mse"] = std::to_string(0.5 / double(i + 1));
  r.row["cos_rmse"] = std::to_string(0.25 / double(i + 1));
  r.row["storage_floats"] = std::to_string(16 * (i + 1));
  r.row["seconds"] = "0.5";
  return r;
}

ExperimentOutput hostile_output(const std::string& dir, size_t runs) {
  ExperimentOutput e;
  e.dir = dir;
  e.experiment = {{"name", "hostile"}, {"description", "<!--<script> a\n# injected heading\n<b>bold</b> | x"}};
  e.config_path = "cfg`with`ticks\n# heading.toml";
  e.config_text = "# <!--<script></script> & \"q\"\n";
  e.defines = {"method.label=`x`\n# h"};
  for (size_t i = 0; i < runs; ++i) e.runs.push_back(hostile_run(i));
  e.plots = false;
  return e;
}

// The cells of a markdown table row, split as GFM does: a backslash escapes
// the next character, an unescaped '|' ends a cell.
std::vector<std::string> md_cells(const std::string& line) {
  std::vector<std::string> cells;
  std::string cur;
  for (size_t i = 0; i < line.size(); ++i) {
    if (line[i] == '\\' && i + 1 < line.size()) {
      cur += line.substr(i, 2);
      ++i;
    } else if (line[i] == '|') {
      cells.push_back(cur);
      cur.clear();
    } else {
      cur += line[i];
    }
  }
  cells.push_back(cur);
  // "| a | b |": the text before the first and after the last pipe is empty.
  if (!cells.empty() && cells.front().empty()) cells.erase(cells.begin());
  if (!cells.empty() && cells.back().empty()) cells.pop_back();
  return cells;
}

// What markdown shows for md_text's output: backslash escapes and the
// entities it writes undone.
std::string md_shown(std::string s) {
  std::string o;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '\\' && i + 1 < s.size() && std::ispunct(static_cast<unsigned char>(s[i + 1]))) {
      o += s[++i];
      continue;
    }
    bool done = false;
    for (const auto& [ent, ch] : {std::pair<const char*, const char*>{"&amp;", "&"}, {"&lt;", "<"}, {"&gt;", ">"},
                                  {"&#32;", " "}})
      if (s.compare(i, std::strlen(ent), ent) == 0) {
        o += ch;
        i += std::strlen(ent) - 1;
        done = true;
        break;
      }
    if (!done) o += s[i];
  }
  return o;
}

// The text a one-line context shows: line breaks as one space, other control
// characters as U+FFFD.
std::string one_line(const std::string& s) {
  std::string o;
  for (size_t i = 0; i < s.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c == '\r' && i + 1 < s.size() && s[i + 1] == '\n') continue;
    if (c == '\n' || c == '\r' || c == '\t' || c == '\v' || c == '\f') o += ' ';
    else if (c < 0x20 || c == 0x7f) o += "\xEF\xBF\xBD";
    else o += char(c);
  }
  return o;
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t p = 0; (p = text.find(what, p)) != std::string::npos; p += what.size()) ++n;
  return n;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

// Sets an environment variable for the scope.
struct ScopedEnv {
  std::string name;
  ScopedEnv(const std::string& n, const std::string& v) : name(n) { setenv(n.c_str(), v.c_str(), 1); }
  ~ScopedEnv() { unsetenv(name.c_str()); }
};

}  // namespace

TEST_CASE("strings by context: results.md keeps one line per row and its columns, shows the text, no raw HTML",
          "[escape]") {
  ScratchDir dir;
  const size_t n = hostile().size();
  const ExperimentOutput e = hostile_output(dir.path.string(), n);
  const OutputFiles f = write_experiment_outputs(e, nullptr);
  const std::string md = read_text(f.results_md);
  INFO(md);
  const auto lines = lines_of(md);
  // One heading (the title): the description, labels and paths inject none.
  size_t headings = 0;
  for (const auto& l : lines) headings += !l.empty() && l[0] == '#';
  CHECK(headings == 1);
  CHECK(lines.at(0) == "# Experiment hostile");
  // The table: the header, the separator, one line per run, each with the
  // header's column count; no other line starts with '|'.
  std::vector<size_t> rows;
  for (size_t i = 0; i < lines.size(); ++i)
    if (!lines[i].empty() && lines[i][0] == '|') rows.push_back(i);
  REQUIRE(rows.size() == n + 2);
  for (size_t k = 1; k < rows.size(); ++k) CHECK(rows[k] == rows[0] + k);
  const auto header = md_cells(lines[rows[0]]);
  for (size_t k = 1; k < rows.size(); ++k) {
    INFO(lines[rows[k]]);
    CHECK(md_cells(lines[rows[k]]).size() == header.size());
  }
  // Each text column shows the run's text, on one line.
  auto column = [&](const std::string& name) {
    for (size_t c = 0; c < header.size(); ++c)
      if (md_shown(header[c]) == " " + name + " ") return c;
    FAIL("no column " << name);
    return size_t(0);
  };
  for (const char* col : {"brdf", "label", "notes", "sweep"}) {
    const size_t c = column(col);
    for (size_t i = 0; i < n; ++i) {
      const std::string cell = md_cells(lines[rows[2 + i]]).at(c);
      INFO(col << " of run " << i << ": " << cell);
      CHECK(md_shown(cell) == " " + one_line(e.runs[i].row.at(col)) + " ");
    }
  }
  // No raw HTML and no markdown that the text did not ask for: every '<' is
  // the start of nothing, every '&' an entity md_text wrote.
  CHECK(md.find('<') == std::string::npos);
  CHECK(md.find("<b>") == std::string::npos);
  CHECK(md.find("<!--") == std::string::npos);
  CHECK(md.find('\x1b') == std::string::npos);
  CHECK(md.find('\r') == std::string::npos);
  // The description is one paragraph, the config path one code span.
  CHECK(md.find(md_text(e.experiment["description"].get<std::string>())) != std::string::npos);
  CHECK(md.find(md_code(e.config_path)) != std::string::npos);
}

TEST_CASE("strings by context: markdown escapers neutralize block and inline syntax at any position", "[escape]") {
  for (const auto& s : hostile()) {
    INFO(s);
    const std::string t = md_text(s);
    CHECK(t.find('\n') == std::string::npos);
    CHECK(t.find('\r') == std::string::npos);
    CHECK(md_shown(t) == one_line(s));
    CHECK(md_cells("|" + t + "|").size() == 1);
  }
  // Block markers at the start; numbers stay readable.
  CHECK(md_text("- a") == "\\- a");
  CHECK(md_text("+") == "\\+");
  CHECK(md_text("1. a") == "1\\. a");
  CHECK(md_text("12)") == "12\\)");
  CHECK(md_text("1.5e-05") == "1.5e-05");
  CHECK(md_text("-0.25") == "-0.25");
  CHECK(md_text("  x") == "&#32; x");
  CHECK(md_text("a\r\nb") == "a b");
  // Code spans: a fence longer than any run of backticks inside.
  CHECK(md_code("a") == "`a`");
  CHECK(md_code("a`b") == "``a`b``");
  CHECK(md_code("``x") == "``` ``x ```");
  CHECK(md_code("p\nq") == "`p q`");
}

TEST_CASE("strings by context: report.html holds no raw markup from user text and its JSON parses back",
          "[escape]") {
  // The same page with harmless strings counts the page's own markup.
  auto page = [](const std::string& dir, bool harmful) {
    ExperimentOutput e = hostile_output(dir, hostile().size());
    if (!harmful) {
      e.experiment["description"] = "plain";
      e.config_path = "cfg.toml";
      e.config_text = "x = 1\n";
      e.defines = {"a=b"};
      for (auto& r : e.runs)
        for (const char* c : {"brdf", "label", "notes", "sweep"}) r.row[c] = "plain";
    }
    // Two runs have viewer data (those named "<!--<script>" and "</script>..."):
    // the viewer section and its embedded list.
    for (size_t i : {6, 7}) write_text(dir + "/runs/" + e.runs[i].run_id + "/viewer.js", "// data\n");
    write_experiment_outputs(e, nullptr);
    return std::make_pair(e, read_text(dir + "/report.html"));
  };
  ScratchDir a, b;
  const auto [e, html] = page(a.path.string(), true);
  const std::string plain = page(b.path.string(), false).second;
  INFO(html.substr(0, 4000));
  for (const char* markup : {"<script", "</script", "<!--", "<b>", "<h1", "<h2", "<h3", "<tr", "<a ", "<pre"}) {
    INFO(markup);
    CHECK(count(html, markup) == count(plain, markup));
  }
  CHECK(count(html, "<!--") == 0);
  // None of the characters & < > " ' of the user's text appears raw.
  for (const char* raw : {"X&Y", "X<Y", "X>Y", "X\"Y", "X'Y", "<b>x</b>", "<!--<script>", "</script><script>",
                          "alert(1)</script>"}) {
    INFO(raw);
    CHECK(html.find(raw) == std::string::npos);
  }
  // The viewer's run list: a script element whose JSON parses back to the
  // labels the page shows for those runs.
  const std::string key = "window.BF_VIEWER_FILES = ";
  const size_t at = html.find(key);
  REQUIRE(at != std::string::npos);
  const size_t end = html.find(";\n", at);
  REQUIRE(end != std::string::npos);
  const std::string text = html.substr(at + key.size(), end - at - key.size());
  INFO(text);
  CHECK(text.find_first_of("<>&") == std::string::npos);
  CHECK(text.find("\xE2\x80\xA8") == std::string::npos);
  CHECK(text.find("\xE2\x80\xA9") == std::string::npos);
  const auto list = nlohmann::json::parse(text);
  REQUIRE(list.size() == 2);
  for (size_t k = 0; k < 2; ++k) {
    const auto& run = e.runs[6 + k];
    CHECK(list[k].at("id") == run.run_id);
    CHECK(list[k].at("label") == run.row.at("brdf") + " | " + run.row.at("label") + " " + run.row.at("sweep"));
  }
  // The script JSON of every hostile string parses back to it.
  for (const auto& s : hostile()) {
    const std::string j = script_json(nlohmann::json{{"s", s}});
    INFO(j);
    CHECK(j.find_first_of("<>&") == std::string::npos);
    CHECK(nlohmann::json::parse(j).at("s") == s);
  }
  CHECK(html_text("<&>\"'") == "&lt;&amp;&gt;&quot;&#39;");
}

TEST_CASE("strings by context: plots draw labels and BRDF names with mathtext and TeX syntax as plain text",
          "[escape]") {
  const std::string py = find_python(nullptr);
  // matplotlib is installed by scripts/install-deps.sh: missing, the test fails.
  INFO("no python3 with matplotlib (scripts/install-deps.sh installs python3-matplotlib)");
  REQUIRE(!py.empty());
  ScratchDir dir;
  ExperimentOutput e = hostile_output(dir.path.string(), 6);
  const std::vector<std::string> labels = {"$x$", "$", "\\", "_hidden", "a^b % {c} _d", "$\\frac{1}{$"};
  for (size_t i = 0; i < e.runs.size(); ++i) {
    e.runs[i].row["label"] = labels[i];
    e.runs[i].row["brdf"] = i % 2 ? "$\\alpha$ {x}" : "b_$1";
    e.runs[i].row["sweep"] = "label=" + labels[i];
  }
  e.plots = true;
  const OutputFiles f = write_experiment_outputs(e, nullptr);
  INFO(f.plots_note);
  CHECK(f.plots_note.empty());
  CHECK(f.plots.size() >= 3);
  for (const auto& p : f.plots) {
    INFO(p);
    CHECK(fs::file_size(dir.path / p) > 1000);
  }
  CHECK(!fs::exists(dir.path / "plots.log"));  // kept only when the script fails
}

TEST_CASE("strings by context: a failing plot step exits 2 with one line, the tables written, the traceback in a log",
          "[escape]") {
  ScratchDir dir;
  const std::string script = write_text(dir / "failing_plot.py",
                                        "import sys\n"
                                        "def draw():\n"
                                        "    raise RuntimeError('deliberate plot failure')\n"
                                        "draw()\n");
  const ScopedEnv env("BRDF_FACTOR_PLOT_SCRIPT", script);
  const std::string cfg = write_text(dir / "cfg.toml", std::string(kConfigHead) +
                                                           "[[method]]\nkind = \"mccool\"\ntexture_size = 4\n");
  std::string err;
  const int code = run_cli_stderr("run " + cfg + " --out " + (dir / "out") + " -q", &err);
  INFO(err);
  if (find_python(nullptr).empty()) {
    // No python with matplotlib: the plots are skipped with a note, not an error.
    CHECK(code == 0);
    return;
  }
  CHECK(code == 2);
  // One line on stderr naming the script and the failure, no traceback.
  CHECK(count(err, "\n") == 1);
  CHECK(err.find("failing_plot.py") != std::string::npos);
  CHECK(err.find("deliberate plot failure") != std::string::npos);
  CHECK(err.find("Traceback") == std::string::npos);
  // The tables are written; results.md names the failure in one line.
  CHECK(read_results_csv(dir / "out/results.csv").size() == 1);
  const std::string md = read_text(dir / "out/results.md");
  INFO(md);
  CHECK(md.find("deliberate plot failure") != std::string::npos);
  CHECK(md.find("Traceback") == std::string::npos);
  CHECK(md.find("line 3") == std::string::npos);
  const std::string html = read_text(dir / "out/report.html");
  CHECK(html.find("deliberate plot failure") != std::string::npos);
  CHECK(html.find("Traceback") == std::string::npos);
  // The whole output in the log.
  const std::string log = read_text(dir / "out/plots.log");
  CHECK(log.find("Traceback") != std::string::npos);
  CHECK(log.find("deliberate plot failure") != std::string::npos);
}

TEST_CASE("strings by context: the viewer loads for a run whose BRDF name and label hold script and comment markup",
          "[escape]") {
  const std::string browser = chromium_browser();
  // Installed by scripts/install-deps.sh: missing, the test fails.
  INFO("chromium not installed (scripts/install-deps.sh installs it)");
  REQUIRE(!browser.empty());
  ScratchDir dir;
  const std::string cfg = write_text(dir / "viewer.toml", R"(
[experiment]
name = "viewer-hostile"
plots = false
[[brdf]]
preset = "bluepaint"
name = "B<!--<script>&\"'</script>"
[sampling]
kind = "grid"
resolution = 6
[scene]
size = 16
[[method]]
kind = "mccool"
texture_size = 4
label = "L<!--<script>\u2028</script><script>x"
)");
  const RunSummary s = run_quiet(cfg, dir / "out");
  REQUIRE(s.failed == 0);
  const std::string page = dir / "out/report.html";
  const std::string html = read_text(page);
  REQUIRE(html.find("id=\"viewer\"") != std::string::npos);
  CHECK(html.find("<!--") == std::string::npos);
  const std::string dom = dir / "dom.html";
  const std::string cmd =
      chromium_command(browser, "--dump-dom 'file://" + page + "#viewer-test' > " + dom + " 2> " + (dir / "chromium.log"));
  REQUIRE(std::system(cmd.c_str()) == 0);
  const std::string text = read_text(dom);
  // The viewer ran: its status is no longer "loading..." and the test block
  // holds the run's numbers.
  const size_t st = text.find("<span id=\"v-status\">");
  REQUIRE(st != std::string::npos);
  CHECK(text.compare(st, 27, "<span id=\"v-status\"></span>") == 0);
  const size_t at = text.find("<pre id=\"viewer-test\"");
  REQUIRE(at != std::string::npos);
  const size_t open = text.find('>', at) + 1, close = text.find("</pre>", open);
  REQUIRE(close != std::string::npos);
  // The dump serializes the block's text with &lt; &gt; &amp;.
  std::string block = text.substr(open, close - open);
  for (const auto& [ent, ch] : {std::pair<std::string, std::string>{"&lt;", "<"}, {"&gt;", ">"}, {"&amp;", "&"}})
    for (size_t p = 0; (p = block.find(ent, p)) != std::string::npos; p += ch.size()) block.replace(p, ent.size(), ch);
  std::istringstream lines(block);
  std::string line;
  int runs = 0;
  while (std::getline(lines, line)) {
    if (line.empty()) continue;
    const auto j = nlohmann::json::parse(line);
    if (j.contains("drag")) {
      // The info line shows the label as text.
      const std::string info = j["drag"].at("info").get<std::string>();
      INFO(info);
      CHECK(info.find("B<!--<script>&\"'</script>") != std::string::npos);
      CHECK(info.find("L<!--<script>\xE2\x80\xA8</script><script>x") != std::string::npos);
      continue;
    }
    if (!j.contains("run")) {
      // The slider, slice, compare and shape records (viewer_test.cpp checks
      // their numbers): drawn without an error.
      INFO(line.substr(0, 300));
      const auto& rec = j.begin().value();
      CHECK(rec.value("status", std::string()).empty());
      continue;
    }
    INFO(line.substr(0, 300));
    CHECK(!j.contains("error"));
    CHECK(j.at("approx").size() == size_t(16 * 16 * 3));
    ++runs;
  }
  CHECK(runs == 1);
}
