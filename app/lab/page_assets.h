// app/lab/page_assets.h -- the scripts and style sheet the HTML pages inline (run_html.h,
// sweep_html.h), compiled into cdlab from app/lab/page/ and Debian's libjs-chart.js by
// app/lab/page/embed_assets.cmake, so a page needs no network and no file beside it.
#pragma once

#include <string_view>

namespace app {

/// Chart.js (Debian package libjs-chart.js, chart.min.js, UMD build: defines `Chart`).
std::string_view chartJs();
/// The script of a run's index.html (app/lab/page/run_page.js).
std::string_view runPageJs();
/// The script of a sweep's report.html (app/lab/page/sweep_page.js).
std::string_view sweepPageJs();
/// The script of `cdlab serve`'s page (app/lab/page/serve_page.js).
std::string_view servePageJs();
/// The style sheet of every page (app/lab/page/page.css).
std::string_view pageCss();

}  // namespace app
