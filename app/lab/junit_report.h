// app/lab/junit_report.h -- the JUnit XML report of `cdlab check --junit FILE`, as CI systems
// read it (GitLab `artifacts:reports:junit`, Jenkins, GitHub test reporters): one <testsuite> per
// scene, one <testcase> per expectation. tests/data/junit_cdlab.xsd is the schema it follows.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "check.h"

namespace app {

/// `text` as XML 1.0 character data (`attribute` false) or as the value of a double-quoted
/// attribute (`attribute` true): & < > " ' as entities, tab/newline/carriage return as
/// character references in attributes (they would be normalised to spaces), carriage return
/// also in text; the bytes XML 1.0 cannot carry at all -- other control characters, bytes that
/// are not well-formed UTF-8, U+FFFE and U+FFFF -- as the visible text `\xNN` per byte.
std::string xmlEscape(std::string_view text, bool attribute);

/// The report: <testsuites> with the totals and `total_seconds` (wall-clock of the whole check),
/// then per scene in order a <testsuite name=SCENE tests failures errors time> whose testcases
/// are its rows (classname = scene, name = the expectation as the table prints it). A failed
/// expectation carries <failure message=REASON>; a scene that did not load or could not run has
/// its one row as an <error> (errors="1"). The scene's time is its SceneReport::seconds; a
/// testcase has no time of its own (all expectations of a scene are graded from one run).
/// Loader notes and a child's output go to the suite's <system-err>.
std::string junitXml(const std::vector<SceneReport>& reports, double total_seconds);

}  // namespace app
