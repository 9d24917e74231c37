// Text of user origin (BRDF names, method labels, descriptions, file names,
// notes, config values, error messages) written into a page: one escaper per
// output context (docs/robustness.md, "Strings by context"). Each returns text
// that the context shows as exactly the given characters (markdown: on one
// line) and that cannot start markup, a tag, a comment or a script.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace bf {

// Markdown inline text: a table cell, a heading's text, a paragraph. Line
// breaks (LF, CR, CRLF, tab, VT, FF) become one space and other control
// characters U+FFFD, so the text stays on its line; & < > become entities (no
// raw HTML, no autolink); \ ` * _ [ ] # | ~ $ are backslash-escaped (no code
// span, emphasis, link, heading, cell split, strikethrough or math); at the
// start, a block marker (- + = followed by no letter or digit, "1." / "1)",
// a space) is neutralized, so the text may also begin a line.
std::string md_text(const std::string& s);

// A markdown code span holding s literally (outside tables): fenced with one
// backtick more than the longest run of backticks in s; line breaks become
// spaces and other control characters U+FFFD.
std::string md_code(const std::string& s);

// A relative path as a URL (markdown link destination or an HTML href/src):
// every byte but letters, digits and / . _ - percent-encoded.
std::string url_path(const std::string& rel);

// HTML text and (quoted) attribute values: & < > " ' as entities.
std::string html_text(const std::string& s);

// JSON for a <script> element of an HTML page (or a .js file): nlohmann's
// dump with invalid UTF-8 replaced by U+FFFD, then < > & ' and U+2028/U+2029
// written as \u003c \u003e \u0026 \u0027 \u2028 \u2029. They occur only inside JSON
// strings, so the value parses back unchanged, and "</script", "<!--" and
// "<script" can never appear in the text.
std::string script_json(const nlohmann::json& j);

}  // namespace bf
