// app/lab/markup_entity.h -- the five characters markup gives a meaning (& < > " '), written as
// entities; shared by the HTML pages (html_page.h) and the JUnit XML (junit_report.h), which add
// their own rules for everything else.
#pragma once

#include <string_view>

namespace app {

/// The entity of `c` if it is one of & < > " ', else empty. `apostrophe` is how the document
/// spells ': "&#39;" for HTML (HTML 4 has no &apos;), "&apos;" for XML.
inline std::string_view markupEntity(char c, std::string_view apostrophe) {
    switch (c) {
        case '&':
            return "&amp;";
        case '<':
            return "&lt;";
        case '>':
            return "&gt;";
        case '"':
            return "&quot;";
        case '\'':
            return apostrophe;
        default:
            return {};
    }
}

}  // namespace app
