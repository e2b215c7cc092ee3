// app/lab/html_page.h -- what every cdlab HTML page shares (run_html.h, sweep_html.h): text
// escaped for HTML, data embedded as JSON, and the page's frame with its inlined style sheet and
// scripts, so that a page is one self-contained file.
#pragma once

#include <string>
#include <string_view>

namespace app::html {

/// `text` safe inside an element or a quoted attribute: & < > " ' as character references.
std::string escape(std::string_view text);

/// `path` (a relative or absolute file path, '/'-separated) as the path of a URL: every byte but
/// letters, digits, - . _ ~ and / percent-encoded, so '#', '?' or a space in a file name
/// cannot cut the link short. An absolute path becomes a file:// URL.
std::string urlPath(std::string_view path);

/// A <script type="application/json" id=ID> element holding `json` (valid JSON text), with every
/// < > & written as \u003c \u003e \u0026: no string in the data (a scene or body name) can
/// close the element or open a comment, and JSON.parse() gives the same data back.
std::string jsonScript(std::string_view id, std::string_view json);

/// The page up to and including <body>: doctype, UTF-8, `title` (escaped), the style sheet.
std::string pageStart(std::string_view title);

/// Chart.js, then `page_script`, each in a <script> element, then </body></html>.
std::string pageEnd(std::string_view page_script);

}  // namespace app::html
