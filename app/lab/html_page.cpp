// app/lab/html_page.cpp -- see html_page.h.
#include "html_page.h"

#include "markup_entity.h"
#include "page_assets.h"

namespace app::html {

std::string escape(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (const char c : text) {
        const std::string_view entity = markupEntity(c, "&#39;");
        if (entity.empty()) {
            out += c;
        } else {
            out += entity;
        }
    }
    return out;
}

std::string urlPath(std::string_view path) {
    std::string out = !path.empty() && path.front() == '/' ? "file://" : "";
    for (const char c : path) {
        const unsigned char u = static_cast<unsigned char>(c);
        if ((u >= 'a' && u <= 'z') || (u >= 'A' && u <= 'Z') || (u >= '0' && u <= '9') ||
            c == '-' || c == '.' || c == '_' || c == '~' || c == '/') {
            out += c;
            continue;
        }
        constexpr char kHex[] = "0123456789ABCDEF";
        out += '%';
        out += kHex[u >> 4];
        out += kHex[u & 15];
    }
    return out;
}

std::string jsonScript(std::string_view id, std::string_view json) {
    std::string out = "<script type=\"application/json\" id=\"";
    out += escape(id);
    out += "\">";
    // < > & occur in JSON only inside strings, where \u escapes mean the same characters.
    for (const char c : json) {
        switch (c) {
            case '<':
                out += "\\u003c";
                break;
            case '>':
                out += "\\u003e";
                break;
            case '&':
                out += "\\u0026";
                break;
            default:
                out += c;
        }
    }
    out += "</script>\n";
    return out;
}

std::string pageStart(std::string_view title) {
    std::string out =
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>";
    out += escape(title);
    out += "</title>\n<style>\n";
    out += pageCss();
    out += "</style>\n</head>\n<body>\n";
    return out;
}

std::string pageEnd(std::string_view page_script) {
    // Both scripts were checked for "</script" when they were compiled in (embed_assets.cmake).
    std::string out = "<script>\n";
    out += chartJs();
    out += "\n</script>\n<script>\n";
    out += page_script;
    out += "\n</script>\n</body>\n</html>\n";
    return out;
}

}  // namespace app::html
