// tests/app/check_workers_test.cpp -- `cdlab check` over many scenes: -j N grades them in child
// processes and prints the same table as -j 1; --keep-going and --junit grade the scenes that
// load when one does not; a child that crashes, exits early or hangs (--timeout) costs only its
// own row; the JUnit report says what the table says.
//
// The scenes: two unit-diameter spheres 3.1 m apart closing at 2 m/s along x, no response, so
// they collide in frames 11..20 (dt = 0.1 s, one step per frame); `extra` bodies stay far away.
#include "check_workers.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "check.h"
#include "cli_run.h"

namespace app {
namespace {

namespace fs = std::filesystem;
using cdlab_test::CliResult;
using cdlab_test::runCdlab;
using cdlab_test::slurp;

fs::path checkManyDir(const std::string& name) { return cdlab_test::tempDir("cdlab_check_many_", name); }

std::string scene(const std::string& expect, int extra = 1, const std::string& world = "") {
    std::string s =
        "world: {bounds: {min: [-4, -4, -4], max: [4, 4, 4]}, time_step: 0.1, frames: 25" + world +
        "}\n"
        "output: {width: 160, height: 120, fps: 10}\n"
        "camera: {position: [0, 0, 12], look_at: [0, 0, 0]}\n"
        "bodies:\n"
        "  - {name: a, shape: sphere, radius: 0.5, position: [-1.55, 0, 0], velocity: [1, 0, 0]}\n"
        "  - {name: b, shape: sphere, radius: 0.5, position: [1.55, 0, 0], velocity: [-1, 0, 0]}\n";
    for (int k = 0; k < extra; ++k) {
        s += "  - {name: c" + std::to_string(k) + ", shape: sphere, radius: 0.3, position: [" +
             std::to_string(-3 + k) + ", 3, -2]}\n";
    }
    return s + "expect:\n" + expect;
}

const std::string kCollide = "  pairs:\n    - {a: a, b: b, frames: [11, 20], colliding: true}\n";
const std::string kCollideTooEarly =
    "  pairs:\n    - {a: a, b: b, frames: [9, 20], colliding: true}\n";

void write(const fs::path& file, const std::string& text) {
    fs::create_directories(file.parent_path());
    std::ofstream(file, std::ios::binary) << text;
}

// The course's folder: a scene that passes, one that fails, one that does not load, and two
// students' scenes of the same file name, each with a pause dump of its own. Had the two dumps
// shared a folder, one student's pause_2.json would list the other's body count and fail.
struct Course {
    fs::path dir;
    std::string all;       ///< every scene, as arguments
    std::string loadable;  ///< every scene but the broken one
};

Course makeCourse(const fs::path& work) {
    Course c{work / "course", "", ""};
    write(c.dir / "good.yaml", scene(kCollide));
    write(c.dir / "wrong.yaml", scene(kCollideTooEarly));
    write(c.dir / "broken.yaml",
          scene("  pairs:\n    - {a: a, b: zz, frames: 1, colliding: true}\n"));
    write(c.dir / "students/a/scene.yaml", scene("  pause_dumps: [2]\n  min_bodies: 3\n", 1));
    write(c.dir / "students/b/scene.yaml", scene("  pause_dumps: [2]\n  min_bodies: 5\n", 2));
    for (const char* f : {"good.yaml", "wrong.yaml", "broken.yaml", "students/a/scene.yaml",
                          "students/b/scene.yaml"}) {
        const std::string path = (c.dir / f).string();
        c.all += ' ';
        c.all += path;
        if (std::string(f) == "broken.yaml") continue;
        c.loadable += ' ';
        c.loadable += path;
    }
    return c;
}

// The line of `table` whose scene column is `label` and whose expectation starts with `what`.
std::string tableRow(const std::string& table, const std::string& label, const std::string& what) {
    std::istringstream lines(table);
    for (std::string line; std::getline(lines, line);) {
        if (line.rfind(label + " ", 0) != 0) continue;
        const std::size_t col = line.find_first_not_of(' ', label.size());
        if (col != std::string::npos && line.compare(col, what.size(), what) == 0) return line;
    }
    return "(no row " + label + " / " + what + ")";
}

// runCdlab for the runs whose stderr is compared across -j: LeakSanitizer (the sanitizer build)
// prints its "Suppressions used" summary at the exit of every process, the check's and each
// child's; that is the sanitizer's output, not cdlab's.
CliResult runCompared(const std::string& args, const fs::path& work) {
    return runCdlab(args, work,
                    "LSAN_OPTIONS=\"${LSAN_OPTIONS:+$LSAN_OPTIONS:}print_suppressions=0\"");
}

// A report without its time="..." attributes (std::regex warns under GCC 12's sanitizer build).
std::string withoutTimes(std::string xml) {
    for (std::size_t at; (at = xml.find(" time=\"")) != std::string::npos;) {
        xml.erase(at, xml.find('"', at + 7) + 1 - at);
    }
    return xml;
}

TEST(CheckCli, SameTableAndExitCodeForEveryJobCount) {
    const fs::path work = checkManyDir("jobs");
    const Course course = makeCourse(work);
    const CliResult one = runCompared("check --keep-going -j 1" + course.all, work);
    const CliResult three = runCompared("check --keep-going -j 3" + course.all, work);
    EXPECT_EQ(one.exit_code, 2) << one.out << one.err;
    EXPECT_EQ(three.exit_code, one.exit_code);
    EXPECT_EQ(three.out, one.out);
    EXPECT_EQ(three.err, one.err);
    for (const char* student : {"students/a/scene.yaml", "students/b/scene.yaml"}) {
        const std::string row = tableRow(three.out, (course.dir / student).string(), "pause dump");
        EXPECT_NE(row.find("  pass"), std::string::npos) << row;
    }
    for (const char* expected :
         {"FAIL    does not hold at frame 9", "FAIL    the scene has 4 bodies",
          "broken.yaml:10:17: expect.pairs[0].b: no body is named 'zz'",
          "5 scenes, 7 expectations, 3 failed, 1 scene not loaded"}) {
        EXPECT_NE(three.out.find(expected), std::string::npos) << expected << "\n" << three.out;
    }
    EXPECT_NE(three.err.find("broken.yaml:10:17: expect.pairs[0].b"), std::string::npos)
        << three.err;

    // Scenes that all load: failure, exit 1, the same table. -j 0 is one per core.
    const CliResult serial = runCompared("check -j 1" + course.loadable, work);
    EXPECT_EQ(serial.exit_code, 1) << serial.out << serial.err;
    for (const char* jobs : {" -j 2", " -j 0", " --jobs 7"}) {
        const CliResult r = runCompared(std::string("check") + jobs + course.loadable, work);
        EXPECT_EQ(r.exit_code, 1) << jobs;
        EXPECT_EQ(r.out, serial.out) << jobs;
    }

    // Without --keep-going a bad scene still stops the check before any scene runs.
    const CliResult strict = runCompared("check -j 3" + course.all, work);
    EXPECT_EQ(strict.exit_code, 2);
    EXPECT_EQ(strict.out, "");
    EXPECT_EQ(strict.err, runCompared("check -j 1" + course.all, work).err);
    fs::remove_all(work);
}

// Pause dumps kept with --out: scene k in OUT/k_STEM, whichever process wrote it.
TEST(CheckCli, ParallelPauseDumpsKeepTheirOwnFolders) {
    const fs::path work = checkManyDir("dumps");
    const Course course = makeCourse(work);
    const fs::path out = work / "dumps";
    const CliResult r = runCdlab("check -j 2 --out " + out.string() + course.loadable, work);
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    // good, wrong, students/a, students/b: the students are scenes 2 and 3.
    const std::string a = slurp(out / "2_scene" / "pause_2.json");
    const std::string b = slurp(out / "3_scene" / "pause_2.json");
    EXPECT_NE(a.find("\"c0\""), std::string::npos) << a;
    EXPECT_EQ(a.find("\"c1\""), std::string::npos) << a;
    EXPECT_NE(b.find("\"c1\""), std::string::npos) << b;
    EXPECT_TRUE(fs::exists(out / "3_scene" / "pause_2.png"));
    fs::remove_all(work);
}

// A scene that would run for minutes (10^7 steps) is stopped; the others are graded.
TEST(CheckCli, TimeoutStopsOnlyTheSlowScene) {
    const fs::path work = checkManyDir("timeout");
    write(work / "good.yaml", scene(kCollide));
    write(work / "slow.yaml",
          scene("  min_bodies: 3\n", 1, ", steps_per_frame: 10, frames: 1000000"));
    // world: frames given twice would be bad input: drop the first one.
    std::string slow = slurp(work / "slow.yaml");
    slow.replace(slow.find("frames: 25, "), 12, "");
    write(work / "slow.yaml", slow);
    const CliResult r = runCdlab("check --timeout 2 -j 2 " + (work / "slow.yaml").string() + " " +
                                     (work / "good.yaml").string(),
                                 work);
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_NE(r.out.find("slow.yaml  run                                          FAIL    could "
                         "not run: timed out after 2 s"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("good.yaml  pair a / b colliding at every frames 11..20  pass"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("2 scenes, 2 expectations, 1 failed"), std::string::npos) << r.out;

    // --timeout alone grades in a child too, one scene at a time.
    const CliResult one = runCdlab("check --timeout 1 " + (work / "slow.yaml").string(), work);
    EXPECT_EQ(one.exit_code, 1);
    EXPECT_NE(one.out.find("could not run: timed out after 1 s"), std::string::npos) << one.out;
    fs::remove_all(work);
}

// Processes whose command line holds `needle` (a zombie's is empty).
std::vector<pid_t> processesMentioning(const std::string& needle) {
    std::vector<pid_t> pids;
    for (const fs::directory_entry& e : fs::directory_iterator("/proc")) {
        const std::string pid = e.path().filename().string();
        if (pid.find_first_not_of("0123456789") != std::string::npos) continue;
        std::string cmdline = slurp(e.path() / "cmdline");
        std::replace(cmdline.begin(), cmdline.end(), '\0', ' ');
        if (cmdline.find(needle) != std::string::npos) pids.push_back(std::stoi(pid));
    }
    return pids;
}

// A check killed from outside (a CI job's timeout) takes its children with it.
TEST(CheckCli, ChildrenDieWithTheCheck) {
    const fs::path work = checkManyDir("orphans");
    const fs::path slow = work / "slow.yaml";
    write(slow, scene("  min_bodies: 3\n", 1, ", steps_per_frame: 10"));
    std::string text = slurp(slow);
    text.replace(text.find("frames: 25"), 10, "frames: 1000000");
    write(slow, text);
    const std::string cmd = std::string(CDLAB_BINARY) + " check -j 2 " + slow.string() + " " +
                            slow.string() + " > /dev/null 2>&1 & echo $! > " +
                            (work / "pid").string();
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    const pid_t parent = std::stoi(slurp(work / "pid"));
    // The two children end their command lines with "-- SCENE" (this folder is this test's own).
    const std::string child = "-- " + slow.string();
    for (int i = 0; i < 500 && processesMentioning(child).size() < 2; ++i) ::usleep(10000);
    EXPECT_EQ(processesMentioning(child).size(), 2u);
    // However soon after their start the parent dies: no window before exec.
    ::kill(parent, SIGKILL);
    std::vector<pid_t> left;
    for (int i = 0; i < 500; ++i) {
        left = processesMentioning(child);
        if (left.empty()) break;
        ::usleep(10000);
    }
    EXPECT_TRUE(left.empty()) << "graders outlived their check";
    for (const pid_t pid : left) ::kill(pid, SIGKILL);
    // What the killed check could not remove: its children's reports and its pause-dump folder.
    const std::string id = std::to_string(parent);
    fs::remove_all(fs::temp_directory_path() / ("cdlab_check_work_" + id));
    fs::remove_all(fs::temp_directory_path() / ("cdlab_check_" + id));
    fs::remove_all(work);
}

TEST(CheckCli, BadParallelFlags) {
    const fs::path work = checkManyDir("flags");
    write(work / "good.yaml", scene(kCollide));
    const std::string good = " " + (work / "good.yaml").string();
    CliResult r = runCdlab("check -j -1" + good, work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--jobs: must be >= 0"), std::string::npos) << r.err;
    for (const char* t : {"0", "-1", "nan"}) {
        r = runCdlab(std::string("check --timeout ") + t + good, work);
        EXPECT_EQ(r.exit_code, 2) << t;
        EXPECT_NE(r.err.find("--timeout: must be > 0 seconds"), std::string::npos) << t << r.err;
    }
    // An unwritable report is found out before any scene runs.
    write(work / "file", "x");
    r = runCdlab("check --junit " + (work / "file" / "report.xml").string() + good, work);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_EQ(r.out, "");
    EXPECT_NE(r.err.find("--junit: cannot create output directory"), std::string::npos) << r.err;
    fs::remove_all(work);
}

// Through the binary: the report validates, its counts are the table's, a YAML body name with
// XML's special characters comes back as written, and -j 3 writes the same report but for times.
TEST(CheckCli, JunitReportSaysWhatTheTableSays) {
    if (std::system("xmllint --version > /dev/null 2>&1") != 0) {
        GTEST_SKIP() << "xmllint (Debian libxml2-utils) not installed";
    }
    const fs::path work = checkManyDir("junit");
    const Course course = makeCourse(work);
    std::string odd = scene(kCollideTooEarly);
    for (std::size_t at; (at = odd.find("{a: a,")) != std::string::npos;) {
        odd.replace(at, 6, "{a: \"x<&>'\\\"\\x01\",");
    }
    odd.replace(odd.find("{name: a,"), 9, "{name: \"x<&>'\\\"\\x01\",");
    write(work / "course" / "odd & <1>.yaml", odd);
    const std::string scenes =
        course.all + " '" + (work / "course" / "odd & <1>.yaml").string() + "'";
    const fs::path xml1 = work / "one.xml";
    const fs::path xml3 = work / "three.xml";
    const CliResult r = runCompared("check --junit " + xml1.string() + scenes, work);
    const CliResult r3 = runCompared("check -j 3 --junit " + xml3.string() + scenes, work);
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;  // broken.yaml; the others were graded
    EXPECT_EQ(r3.exit_code, 2);
    EXPECT_EQ(r3.out, r.out);
    EXPECT_FALSE(fs::exists(xml1.string() + ".partial"));

    auto xmllint = [&](const std::string& args, int* code = nullptr) {
        const fs::path out = work / "xmllint.txt";
        const int status =
            std::system(("xmllint " + args + " > " + out.string() + " 2>&1").c_str());
        if (code) *code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        std::string v = slurp(out);
        if (!v.empty() && v.back() == '\n') v.pop_back();
        return v;
    };
    int code = -1;
    const std::string said = xmllint("--noout --schema " + std::string(CDLAB_SOURCE_DIR) +
                                         "/tests/data/junit_cdlab.xsd " + xml1.string(),
                                     &code);
    EXPECT_EQ(code, 0) << said;
    auto xpath = [&](const std::string& e) {
        return xmllint("--xpath '" + e + "' " + xml1.string());
    };

    // The table's rows and FAILs, counted from its text.
    std::size_t rows = 0, fails = 0;
    std::istringstream lines(r.out);
    std::string line;
    std::getline(lines, line);  // header
    while (std::getline(lines, line)) {
        if (line.find(" scenes, ") != std::string::npos) break;
        ++rows;
        fails += line.find("  FAIL    ") != std::string::npos ? 1 : 0;
    }
    EXPECT_EQ(rows, 8u) << r.out;
    EXPECT_EQ(xpath("count(//testsuite)"), "6");
    EXPECT_EQ(xpath("count(//testcase)"), std::to_string(rows));
    EXPECT_EQ(xpath("count(//failure) + count(//error)"), std::to_string(fails));
    EXPECT_EQ(xpath("count(//error)"), "1");
    EXPECT_EQ(
        xpath("string(//testsuite[3]/testcase/error/@message)"),
        (course.dir / "broken.yaml").string() + ":10:17: expect.pairs[0].b: no body is named 'zz'");
    EXPECT_EQ(xpath("string(//testsuite[6]/@name)"), (work / "course" / "odd & <1>.yaml").string());
    EXPECT_EQ(xpath("string(//testsuite[6]/testcase/@name)"),
              "pair x<&>'\"\\x01 / b colliding at every frames 9..20");
    EXPECT_EQ(xpath("string(//testsuite[6]/testcase/failure/@message)"),
              "does not hold at frame 9");

    // The same report from three processes, times aside.
    EXPECT_EQ(withoutTimes(slurp(xml3)), withoutTimes(slurp(xml1)));
    fs::remove_all(work);
}

// ---- the children, faked: a worker that crashes, gives up, hangs or writes nonsense ----

TEST(CheckWorkers, AChildThatDiesOrHangsCostsOnlyItsRow) {
    const fs::path work = checkManyDir("fake");
    const fs::path worker = work / "worker.sh";
    // argv: check --worker-result REPORT ... -- SCENE
    write(worker,
          "#!/bin/sh\n"
          "ulimit -c 0\n"
          "for a; do scene=$a; done\n"
          "case \"$scene\" in\n"
          "  *crash*) echo about to crash >&2; kill -SEGV $$ ;;\n"
          "  *exit*) echo gave up >&2; exit 3 ;;\n"
          "  *hang*) exec sleep 30 ;;\n"
          "  *garbage*) echo 'not a report' > \"$3\"; exit 0 ;;\n"
          "esac\n");
    fs::permissions(worker, fs::perms::owner_all);
    CheckOptions options;
    options.scenes = {"crash.yaml", "exit.yaml", "hang.yaml", "garbage.yaml"};
    options.keep_going = true;  // the parent does not load them: the children would
    options.jobs = 2;
    options.timeout = 1.0;
    options.worker_exe = worker;
    std::ostringstream out, err;
    EXPECT_EQ(runCheck(options, out, err), 1) << out.str() << err.str();
    for (const char* expected :
         {"crash.yaml    run          FAIL    could not run: the grader was killed by signal 11 "
          "(Segmentation fault)",
          "exit.yaml     run          FAIL    could not run: the grader exited with code 3",
          "hang.yaml     run          FAIL    could not run: timed out after 1 s",
          "garbage.yaml  run          FAIL    could not run: the grader's report is unreadable",
          "4 scenes, 4 expectations, 4 failed"}) {
        EXPECT_NE(out.str().find(expected), std::string::npos) << expected << "\n" << out.str();
    }
    // What each child printed, in scene order.
    EXPECT_EQ(err.str(), "about to crash\ngave up\n");

    // A worker that cannot be started at all.
    options.worker_exe = work / "missing";
    options.scenes = {"a.yaml"};
    out.str("");
    EXPECT_EQ(runCheck(options, out, err), 1);
    EXPECT_NE(out.str().find("could not run: cannot start " + (work / "missing").string()),
              std::string::npos)
        << out.str();
    fs::remove_all(work);
}

TEST(CheckWorkers, ReportRoundTripsAnyBytes) {
    SceneReport r;
    r.outcome = SceneOutcome::Graded;
    r.seconds = 0.1234567890123;
    r.notes = {"note: a\nb", ""};
    r.rows = {{std::string("pair \x01:\n3:x / \0b", 15), true, ""},
              {"rest", false, std::string("moved\n\n9:\xff", 10)}};
    const std::optional<SceneReport> back = parseWorkerReport(formatWorkerReport(r));
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(back->outcome, r.outcome);
    EXPECT_EQ(back->seconds, r.seconds);
    EXPECT_EQ(back->notes, r.notes);
    ASSERT_EQ(back->rows.size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) {
        EXPECT_EQ(back->rows[i].expectation, r.rows[i].expectation);
        EXPECT_EQ(back->rows[i].pass, r.rows[i].pass);
        EXPECT_EQ(back->rows[i].reason, r.rows[i].reason);
    }
    // A child killed while writing leaves no whole report: every cut is rejected.
    const std::string text = formatWorkerReport(r);
    for (std::size_t n = 0; n < text.size(); ++n) {
        EXPECT_FALSE(parseWorkerReport(text.substr(0, n)).has_value()) << n;
    }
    EXPECT_FALSE(parseWorkerReport(text + "x").has_value());
}

}  // namespace
}  // namespace app
