// tests/app/docs_command_lines_test.cpp -- the docs cannot drift from the flags: every cdlab
// command line shown in a code block of README.md or docs/*.md goes through `cdlab --dry-run`,
// the real parser and the real checks of a run (flags, value types, scenes loaded, named files
// present, relative to the repository), and must pass silently. Synopses (with `[`, `|`, `...`
// or upper-case placeholders such as SCENE) are skipped; every other line is checked.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cli_run.h"

namespace {

namespace fs = std::filesystem;
using cdlab_test::runCdlab;
using cdlab_test::slurp;
using cdlab_test::tempDir;

/// One cdlab command line found in a Markdown file.
struct DocLine {
    std::string file;  ///< the document, relative to the repository
    int line = 0;      ///< its first line, from 1
    std::string args;  ///< what follows `cdlab `: `run scenes/x.yaml --frames 3`
};

std::string docTrimmed(const std::string& s) {
    const std::size_t a = s.find_first_not_of(" \t");
    if (a == std::string::npos) return "";
    const std::size_t b = s.find_last_not_of(" \t\r");
    return s.substr(a, b - a + 1);
}

// The line without a trailing shell comment (` # ...` outside quotes).
std::string docWithoutComment(const std::string& s) {
    char quote = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        const char c = s[i];
        if (quote != 0) {
            if (c == quote) quote = 0;
        } else if (c == '\'' || c == '"') {
            quote = c;
        } else if (c == '#' && (i == 0 || s[i - 1] == ' ' || s[i - 1] == '\t')) {
            return s.substr(0, i);
        }
    }
    return s;
}

// A usage synopsis rather than a command: optional parts, alternatives, repetition, or an
// upper-case placeholder (SCENE, DIR/plan.json, KEY=V1,V2, FILE.csv).
bool docIsSynopsis(const std::string& args) {
    if (args.find_first_of("[|") != std::string::npos) return true;
    if (args.find("...") != std::string::npos || args.find("\u2026") != std::string::npos) {
        return true;
    }
    static const std::regex placeholder("(^|[^A-Za-z0-9_./-])[A-Z][A-Z0-9_]+([^a-z0-9_]|$)");
    return std::regex_search(args, placeholder);
}

/// The cdlab command lines of a Markdown text's fenced code blocks: a line starting with
/// `build/bin/cdlab ` or `cdlab ` (after indentation), joined with the lines its trailing
/// backslashes continue onto, its shell comment dropped; synopses left out.
std::vector<DocLine> docCommandLines(const std::string& file, const std::string& text) {
    std::vector<DocLine> found;
    std::istringstream in(text);
    bool in_block = false;
    int number = 0;
    std::string raw;
    while (std::getline(in, raw)) {
        ++number;
        const std::string line = docTrimmed(raw);
        if (line.rfind("```", 0) == 0) {
            in_block = !in_block;
            continue;
        }
        if (!in_block) continue;
        const int first = number;
        std::string command = line;
        while (!command.empty() && command.back() == '\\' && std::getline(in, raw)) {
            ++number;
            command.back() = ' ';
            command = docTrimmed(command);
            command.append(" ");
            command.append(docTrimmed(raw));
        }
        command = docTrimmed(docWithoutComment(command));
        for (const std::string& prefix : {std::string("build/bin/cdlab "), std::string("cdlab ")}) {
            if (command.rfind(prefix, 0) != 0) continue;
            const std::string args = docTrimmed(command.substr(prefix.size()));
            if (!docIsSynopsis(args)) found.push_back({file, first, args});
        }
    }
    return found;
}

// What `--out P`, `--plan P` and `--record P` name: folders and files an earlier line of a
// document writes, which a later one (`--collect P`, `replay P`) may read.
std::vector<std::string> docProducedFolders(const std::string& args) {
    std::vector<std::string> out;
    std::istringstream words(args);
    std::string word;
    std::string previous;
    while (words >> word) {
        if (previous == "--out" || previous == "--plan" || previous == "--record") {
            out.push_back(word);
        }
        previous = word;
    }
    return out;
}

// True when every line of a dry run's stderr is `FLAG PATH: no such file or folder` for a PATH
// in `produced`.
bool docOnlyMissingProduced(const std::string& err, const std::set<std::string>& produced) {
    static const std::regex missing("^\\S+ (\\S+): no such file or folder$");
    std::istringstream lines(err);
    std::string line;
    bool any = false;
    while (std::getline(lines, line)) {
        std::smatch m;
        if (!std::regex_match(line, m, missing) || produced.count(m[1].str()) == 0) return false;
        any = true;
    }
    return any;
}

/// Runs every line through `cdlab --dry-run` from the repository; returns a report of each one
/// that did not pass (empty when all did). Lines of one document are checked in order, so a
/// folder an earlier line writes (--out, --plan) counts as present for the later ones.
std::string docCheckLines(const std::vector<DocLine>& lines, const fs::path& work) {
    std::string report;
    std::string file;
    std::set<std::string> produced;
    for (const DocLine& d : lines) {
        if (d.file != file) {
            file = d.file;
            produced.clear();
        }
        const cdlab_test::CliResult r = runCdlab("--dry-run " + d.args, work);
        const bool passed = r.exit_code == 0 && r.out.empty() && r.err.empty();
        const bool waits_for_earlier = r.exit_code == 2 && docOnlyMissingProduced(r.err, produced);
        if (!passed && !waits_for_earlier) {
            report += d.file + ":" + std::to_string(d.line) + ": cdlab " + d.args + "\n  exit " +
                      std::to_string(r.exit_code) + ": " + r.out + r.err + "\n";
        }
        for (const std::string& p : docProducedFolders(d.args)) produced.insert(p);
    }
    return report;
}

/// README.md and docs/*.md, relative to the repository, sorted.
std::vector<std::string> docFiles() {
    const fs::path root = CDLAB_SOURCE_DIR;
    std::vector<std::string> files{"README.md"};
    for (const fs::directory_entry& e : fs::directory_iterator(root / "docs")) {
        if (e.is_regular_file() && e.path().extension() == ".md") {
            files.push_back((fs::path("docs") / e.path().filename()).string());
        }
    }
    std::sort(files.begin() + 1, files.end());
    return files;
}

std::vector<DocLine> docAllLines() {
    std::vector<DocLine> all;
    for (const std::string& f : docFiles()) {
        const std::vector<DocLine> lines =
            docCommandLines(f, slurp(fs::path(CDLAB_SOURCE_DIR) / f));
        all.insert(all.end(), lines.begin(), lines.end());
    }
    return all;
}

TEST(DocsCommandLines, ExtractionJoinsContinuationsAndSkipsSynopses) {
    const std::string text =
        "Prose with `cdlab run x.yaml` inline is not a code block.\n"
        "```sh\n"
        "build/bin/cdlab run scenes/coursework.yaml --frames 3 \\\n"
        "    --no-video   # a comment\n"
        "cdlab check scenes/stack.yaml\n"
        "build/bin/cdlab run SCENE [--out DIR]\n"
        "build/bin/cdlab sweep --job DIR/plan.json --run K\n"
        "build/bin/cdlab bench ccd --method conservative|naive\n"
        "parallel --jobs 2 :::: out/plan/jobs.txt\n"
        "  - cdlab check -j 0 submissions/*/scene.yaml\n"
        "```\n"
        "cdlab run outside.yaml\n";
    const std::vector<DocLine> lines = docCommandLines("x.md", text);
    ASSERT_EQ(lines.size(), 2u);
    EXPECT_EQ(lines[0].line, 3);
    EXPECT_EQ(lines[0].args, "run scenes/coursework.yaml --frames 3 --no-video");
    EXPECT_EQ(lines[1].line, 5);
    EXPECT_EQ(lines[1].args, "check scenes/stack.yaml");
}

TEST(DocsCommandLines, EveryDocumentedLineParses) {
    const fs::path work = tempDir("cdlab_docs_", "lines");
    const std::vector<DocLine> lines = docAllLines();
    // The docs show every subcommand at least once in a form that can be checked, so a broken
    // extraction (nothing found) fails here rather than passing on nothing.
    for (const char* sub : {"run ", "check ", "sweep ", "query ", "bench broadphase ", "bench ccd ",
                            "bench narrowphase ", "bench convex "}) {
        EXPECT_TRUE(std::any_of(lines.begin(), lines.end(),
                                [&](const DocLine& d) { return d.args.rfind(sub, 0) == 0; }))
            << "no checkable `cdlab " << sub << "...` line in README.md or docs/*.md";
    }
    EXPECT_GE(lines.size(), 20u);
    EXPECT_EQ(docCheckLines(lines, work), "");
    fs::remove_all(work);
}

// A checker that cannot fail checks nothing: a line with a misspelt flag, a value of the wrong
// type, a scene that does not exist or a bench flag that does not exist must each be reported.
TEST(DocsCommandLines, WrongLinesAreReported) {
    const fs::path work = tempDir("cdlab_docs_", "wrong");
    const std::string text =
        "```sh\n"
        "build/bin/cdlab run scenes/coursework.yaml --pause-at 60 --htlm\n"
        "build/bin/cdlab run scenes/coursework.yaml --frames sixty\n"
        "build/bin/cdlab check scenes/no_such_scene.yaml\n"
        "build/bin/cdlab bench broadphase --sizez 1000\n"
        "build/bin/cdlab query assets/no_such_mesh.obj --self\n"
        "build/bin/cdlab sweep --collect out/never_planned\n"
        "build/bin/cdlab run scenes/coursework.yaml --pause-at 60 --html\n"
        "```\n";
    const std::vector<DocLine> lines = docCommandLines("wrong.md", text);
    ASSERT_EQ(lines.size(), 7u);
    const std::string report = docCheckLines(lines, work);
    for (const char* reported : {"wrong.md:2:", "--htlm", "wrong.md:3:", "wrong.md:4:",
                                 "no_such_scene.yaml", "wrong.md:5:", "--sizez", "wrong.md:6:",
                                 "wrong.md:7:"}) {
        EXPECT_NE(report.find(reported), std::string::npos) << reported << " in\n" << report;
    }
    EXPECT_EQ(report.find("wrong.md:8:"), std::string::npos) << report;  // the good line
    fs::remove_all(work);
}

// A folder a line writes (--plan) may be read by a later line of the same document
// (--collect), not by a line of another document.
TEST(DocsCommandLines, LaterLinesMayReadWhatEarlierLinesWrite) {
    const fs::path work = tempDir("cdlab_docs_", "produced");
    const std::string planned =
        "```sh\n"
        "cdlab sweep scenes/crowd.yaml --vary broadphase=sap,hgrid --plan out/docs_test_plan\n"
        "cdlab sweep --collect out/docs_test_plan\n"
        "```\n";
    EXPECT_EQ(docCheckLines(docCommandLines("a.md", planned), work), "");
    std::vector<DocLine> split = docCommandLines("a.md", planned);
    split[1].file = "b.md";
    EXPECT_NE(docCheckLines(split, work).find("b.md:3:"), std::string::npos);
    EXPECT_FALSE(fs::exists(fs::path(CDLAB_SOURCE_DIR) / "out/docs_test_plan"));
    fs::remove_all(work);
}

// The other direction: every flag a command's --help lists is named on that command's page, so
// a flag added to the code and not to the docs fails here.
TEST(DocsCommandLines, EveryFlagIsOnItsCommandsPage) {
    const fs::path work = tempDir("cdlab_docs_", "flags");
    const std::vector<std::pair<std::string, std::string>> pages = {
        {"run", "docs/run.md"},
        {"check", "docs/check.md"},
        {"sweep", "docs/sweep.md"},
        {"query", "docs/query.md"},
        {"serve", "docs/serve.md"},
        {"replay", "docs/recording.md"},
        {"bench broadphase", "docs/bench.md"},
        {"bench ccd", "docs/bench.md"},
        {"bench convex", "docs/bench.md"},
        {"bench narrowphase", "docs/bench.md"},
    };
    static const std::regex option_line("^\\s+(?:-[A-Za-z],)?(--[a-z][a-z0-9-]*)");
    int flags = 0;
    for (const auto& [command, page] : pages) {
        const cdlab_test::CliResult help = runCdlab(command + " --help", work);
        ASSERT_EQ(help.exit_code, 0) << command;
        const std::string text = slurp(fs::path(CDLAB_SOURCE_DIR) / page);
        std::istringstream lines(help.out);
        std::string line;
        while (std::getline(lines, line)) {
            std::smatch m;
            if (!std::regex_search(line, m, option_line) || m[1] == "--help") continue;
            ++flags;
            const std::regex named(std::regex_replace(m[1].str(), std::regex("-"), "\\-") +
                                   "([^a-z0-9-]|$)");
            EXPECT_TRUE(std::regex_search(text, named))
                << "cdlab " << command << " " << m[1] << " is not in " << page;
        }
    }
    EXPECT_GE(flags, 60);  // the parse of --help found the flags
    // And the common flag, on the page that describes it.
    EXPECT_NE(slurp(fs::path(CDLAB_SOURCE_DIR) / "docs/run.md").find("--dry-run"),
              std::string::npos);
    fs::remove_all(work);
}

// --dry-run runs nothing and writes nothing: no output folder, no report, no JSON, nothing on
// stdout or stderr, exit 0.
TEST(CliDryRun, GoodLinesRunNothingAndWriteNothing) {
    const fs::path work = tempDir("cdlab_dry_", "good");
    const fs::path out = work / "out";
    const std::string tiny = cdlab_test::kTiny;
    const std::vector<std::string> lines = {
        "run " + tiny + " --out " + out.string() + " --stats " + (out / "s.csv").string() +
            " --pause-at 1 --html",
        "check " + tiny + " --out " + out.string() + " --junit " + (out / "j.xml").string(),
        "sweep " + tiny + " --vary broadphase=sap,hgrid --out " + out.string(),
        "sweep " + tiny + " --vary broadphase=sap,hgrid --plan " + out.string(),
        "query assets/torus.obj assets/torus.obj --json",
        "bench broadphase --sizes 100 --frames 2 --json " + (out / "b.json").string(),
        "bench ccd --no-scenes --json " + (out / "c.json").string(),
        "bench convex --queries 10 --json " + (out / "v.json").string(),
        "bench narrowphase --triangles 100 --json " + (out / "n.json").string(),
    };
    for (const std::string& args : lines) {
        const cdlab_test::CliResult r = runCdlab("--dry-run " + args, work);
        EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.err;
        EXPECT_EQ(r.out, "") << args;
        EXPECT_EQ(r.err, "") << args;
        EXPECT_FALSE(fs::exists(out)) << args;
    }
    // `cdlab bench --dry-run ...` (the flag after `bench`) is cdlab-bench's own flag.
    const cdlab_test::CliResult r = runCdlab("bench --dry-run convex --queries 10", work);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out + r.err, "");
    fs::remove_all(work);
}

// A bad line exits as the real run exits, with the real run's message.
TEST(CliDryRun, BadLinesFailAsARealRunFails) {
    const fs::path work = tempDir("cdlab_dry_", "bad");
    const std::string tiny = cdlab_test::kTiny;
    const std::vector<std::string> bad_lines = {"run " + tiny + " --frmaes 2",
                                                "run " + tiny + " --frames abc",
                                                "run " + tiny + " --broadphase nope",
                                                "run " + tiny + " --set world.frames=abc",
                                                "check tests/data/no_such.yaml",
                                                "query assets/torus.obj --self --bv nope",
                                                "sweep " + tiny + " --vary nokey",
                                                "bench broadphase --workload nope",
                                                "bench ccd --reps 0"};
    for (const std::string& args : bad_lines) {
        const cdlab_test::CliResult dry = runCdlab("--dry-run " + args, work);
        const cdlab_test::CliResult real = runCdlab(args, work);
        EXPECT_EQ(dry.exit_code, 2) << args;
        EXPECT_EQ(dry.exit_code, real.exit_code) << args;
        EXPECT_EQ(dry.err, real.err) << args;
        EXPECT_NE(dry.err, "") << args;
    }
    // What a dry run checks beyond the parser: named inputs that a real run reads later.
    for (const std::string& args : {std::string("bench ccd tests/data/no_such_folder"),
                                    std::string("sweep --collect out/no_such_plan")}) {
        const cdlab_test::CliResult dry = runCdlab("--dry-run " + args, work);
        EXPECT_EQ(dry.exit_code, 2) << args;
        EXPECT_NE(dry.err.find("no such file or folder"), std::string::npos) << dry.err;
    }
    fs::remove_all(work);
}

}  // namespace
