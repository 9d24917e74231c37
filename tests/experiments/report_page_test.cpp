// report.html's page layout: a run's notes are folded in a <details> (in the
// results table and on the run's card), cut at a character boundary.
#include <filesystem>
#include <string>

#include "experiments/report/outputs.h"
#include "experiments/report/report.h"
#include "test_common.h"

using namespace bf;
using bf_test::TempDir;

namespace {
size_t count_in_page(const std::string& s, const std::string& what) {
  size_t n = 0;
  for (size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
  return n;
}
// Every byte sequence of `s` is well-formed UTF-8 (no sequence cut short).
bool valid_utf8(const std::string& s) {
  for (size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    const size_t n = c < 0x80 ? 1 : (c >> 5) == 6 ? 2 : (c >> 4) == 14 ? 3 : (c >> 3) == 30 ? 4 : 0;
    if (n == 0 || i + n > s.size()) return false;
    for (size_t k = 1; k < n; ++k)
      if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return false;
    i += n;
  }
  return true;
}
}  // namespace

TEST_CASE("report page: notes are folded in a details element on the table and the run card") {
  TempDir dir("report_page");
  ExperimentOutput e;
  e.dir = dir.path.string();
  e.experiment = {{"name", "notes"}};
  RunEntry r;
  r.run_id = "abc";
  r.status = "ok";
  r.row = {{"run_id", "abc"}, {"brdf", "b"}, {"method", "sh-k"}, {"rel_mse", "0.1"}};
  // A long note whose 57th byte falls inside a two-byte character (theta).
  std::string note(56, 'x');
  note += "\xce\xb8 and then a great deal more text that would make the table row tall. Second sentence.";
  r.row["notes"] = note;
  e.runs.push_back(r);
  OutputFiles f;
  const std::string page = (dir.path / "report.html").string();
  write_report_html(e, f, page);
  const std::string html = bf_test::slurp(page);
  CHECK(count_in_page(html, "<details class=\"notes\">") == 2);
  CHECK(count_in_page(html, note) == 2);  // the whole note, inside the details
  const size_t s0 = html.find("<summary>"), s1 = html.find("</summary>");
  REQUIRE(s0 != std::string::npos);
  const std::string summary = html.substr(s0 + 9, s1 - s0 - 9);
  CHECK(summary == std::string(56, 'x') + "...");
  CHECK(valid_utf8(html));
  // No note: no details.
  e.runs[0].row["notes"] = "";
  write_report_html(e, f, page);
  CHECK(bf_test::slurp(page).find("<details") == std::string::npos);
}
