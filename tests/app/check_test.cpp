// tests/app/check_test.cpp -- `cdlab check`: a scene whose expectations hold passes, one whose
// expectations are wrong fails with the reason, bad input exits 2; and through the binary.
//
// The test scene: two unit-diameter spheres 3.1 m apart closing at 2 m/s along x, so they touch
// at t = 1.05 s and pass through each other (no response) until t = 2.05 s; dt = 0.1 s, one step
// per frame, so they collide in frames 11..20 and nowhere else. A third sphere stays far away.
//
//     a -->   gap 2.1 m   <-- b          c (still)
//    (-1.55)             (1.55)        (0, 2.5, -2)
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "check.h"
#include "cli_run.h"

namespace app {
namespace {

namespace fs = std::filesystem;
using Result = cdlab_test::CliResult;
using cdlab_test::runCdlab;
using cdlab_test::slurp;

const std::string kTwoSpheres =
    "world: {bounds: {min: [-4, -4, -4], max: [4, 4, 4]}, time_step: 0.1, frames: 25}\n"
    "output: {width: 160, height: 120, fps: 10}\n"
    "camera: {position: [0, 0, 12], look_at: [0, 0, 0]}\n"
    "draw: {volumes: [aabb]}\n"
    "bodies:\n"
    "  - {name: a, shape: sphere, radius: 0.5, position: [-1.55, 0, 0], velocity: [1, 0, 0]}\n"
    "  - {name: b, shape: sphere, radius: 0.5, position: [1.55, 0, 0], velocity: [-1, 0, 0]}\n"
    "  - {name: c, shape: sphere, radius: 0.5, position: [0, 2.5, -2]}\n";

fs::path checkDir(const std::string& name) { return cdlab_test::tempDir("cdlab_check_test_", name); }

engine::Scene parse(const std::string& text) { return engine::parseScene(text, "t.yaml", "."); }

const CheckRow* findRow(const std::vector<CheckRow>& rows, const std::string& fragment) {
    for (const CheckRow& r : rows) {
        if (r.expectation.find(fragment) != std::string::npos) return &r;
    }
    // A missing row fails the test with its name, not with a null dereference in the caller.
    ADD_FAILURE() << "no check row contains \"" << fragment << "\"";
    static thread_local CheckRow missing;
    missing = CheckRow{"(missing) " + fragment, false, "no such row"};
    return &missing;
}

TEST(Check, ExpectationsThatHoldPass) {
    const fs::path dir = checkDir("pass");
    const engine::Scene scene =
        parse(kTwoSpheres +
              "expect:\n"
              "  min_bodies: 3\n"
              "  broadphases: [sap, sphere, grid]\n"
              "  energy_drift_max: 0\n"
              "  pause_dumps: [0, 15]\n"
              "  pairs:\n"
              "    - {a: a, b: b, frames: [0, 10], flagged: false}\n"
              "    - {a: a, b: b, frames: [11, 20], colliding: true}\n"
              "    - {a: b, b: a, frames: [21, 24], colliding: false}\n"
              "    - {a: a, b: c, frames: [0, 24], flagged: false}\n"
              "    - {a: a, b: b, frames: [0, 24], when: any, "
              "colliding: true}\n"
              "  colors:\n"
              "    - {frame: 15, present: [red, green], absent: [yellow]}\n"
              "    - {frame: 0, present: [green], absent: [red, yellow]}\n");
    const std::vector<CheckRow> rows = checkScene(scene, 25, dir);
    ASSERT_EQ(rows.size(), 14u);
    for (const CheckRow& r : rows) {
        EXPECT_TRUE(r.pass) << r.expectation << ": " << r.reason;
        EXPECT_TRUE(r.reason.empty()) << r.reason;
    }
    EXPECT_TRUE(fs::exists(dir / "pause_0.png"));
    EXPECT_TRUE(fs::exists(dir / "pause_15.json"));
    fs::remove_all(dir);
}

// Colour expectations are graded on the picture `cdlab run` draws: without draw.volumes, the
// volume the broad phase tests. Two parallel bars turned 45 degrees, 0.6 m apart: their OBBs
// are apart, their AABBs and bounding spheres overlap. Under the obb broad phase the frame shows
// two green OBBs; a checker drawing the default spheres would see them yellow.
TEST(Check, ColoursAreGradedOnTheVolumeTheBroadPhaseTests) {
    const fs::path dir = checkDir("colours");
    const engine::Scene scene = parse(
        "world: {bounds: {min: [-4, -4, -4], max: [4, 4, 4]}, frames: 2}\n"
        "broadphase: obb\n"
        "output: {width: 160, height: 120}\n"
        "camera: {position: [0, 0, 12], look_at: [0, 0, 0]}\n"
        "bodies:\n"
        "  - {name: p, shape: box, half_extents: [2, 0.1, 0.1], position: [0, 0, 0], "
        "euler_deg: [0, 0, 45]}\n"
        "  - {name: q, shape: box, half_extents: [2, 0.1, 0.1], position: [-0.42426, 0.42426, 0], "
        "euler_deg: [0, 0, 45]}\n"
        "expect:\n"
        "  colors:\n"
        "    - {frame: 0, present: [green], absent: [yellow, red]}\n");
    const std::vector<CheckRow> rows = checkScene(scene, 2, dir);
    ASSERT_EQ(rows.size(), 1u);
    EXPECT_TRUE(rows[0].pass) << rows[0].expectation << ": " << rows[0].reason;
    fs::remove_all(dir);
}

TEST(Check, WrongExpectationsFailWithTheReason) {
    const fs::path dir = checkDir("fail");
    // Gravity makes semi-implicit Euler drift in energy; nothing rotates.
    std::string text = kTwoSpheres;
    text.replace(text.find("frames: 25}"), 11, "frames: 25, gravity: [0, -9.81, 0]}");
    const engine::Scene scene = parse(text +
                                      "expect:\n"
                                      "  min_bodies: 4\n"
                                      "  min_moving_rotating: 1\n"
                                      "  energy_drift_max: 1e-12\n"
                                      "  pairs:\n"
                                      "    - {a: a, b: b, frames: [5, 12], colliding: true}\n"
                                      "    - {a: a, b: c, frames: [0, 24], when: any, "
                                      "flagged: true}\n"
                                      "  colors:\n"
                                      "    - {frame: 0, present: [red]}\n");
    const std::vector<CheckRow> rows = checkScene(scene, 25, dir);
    ASSERT_EQ(rows.size(), 6u);
    for (const CheckRow& r : rows) EXPECT_FALSE(r.pass) << r.expectation;
    EXPECT_EQ(findRow(rows, "at least 4 bodies")->reason, "the scene has 3 bodies");
    EXPECT_EQ(findRow(rows, "moving and rotating")->reason,
              "0 of 3 bodies both moved and rotated (> 1 degree) in 25 frames");
    EXPECT_EQ(findRow(rows, "energy")->reason.rfind("relative drift ", 0), 0u)
        << findRow(rows, "energy")->reason;
    EXPECT_EQ(findRow(rows, "pair a / b colliding")->reason, "does not hold at frame 5");
    EXPECT_EQ(findRow(rows, "pair a / c")->reason, "holds at no frame of the range");
    const std::string colour = findRow(rows, "colours red")->reason;
    EXPECT_EQ(colour, "red: 0 pixels, need 20");
    fs::remove_all(dir);
}

// Tunnelling, time of impact, rest and energy rise, each both ways. Without response a passes
// through b: relative to b, a's centre goes from x = -3.1 at 2 m/s and is beyond b's box
// (half extent 0.5) once -3.1 + 2 t > 0.5, t > 1.8 s: frame 19 (the first frame after).
TEST(Check, TunnellingTimeOfImpactRestAndEnergyRise) {
    const fs::path dir = checkDir("motion");
    const engine::Scene off = parse(kTwoSpheres +
                                    "expect:\n"
                                    "  tunnelling:\n"
                                    "    - {a: a, b: b, passes: true}\n"
                                    "    - {a: a, b: b, passes: false}\n"
                                    "    - {a: a, b: c, passes: true}\n"
                                    "  toi:\n"
                                    "    - {a: a, b: b, time: 1.05, tolerance: 0.01}\n"
                                    "  rest:\n"
                                    "    - {body: c, frames: [0, 24], max_displacement: 0, "
                                    "max_speed: 0}\n"
                                    "    - {body: a, frames: [3, 6], max_displacement: 0.25, "
                                    "max_speed: 0.5}\n");
    std::vector<CheckRow> rows = checkScene(off, 25, dir);
    ASSERT_EQ(rows.size(), 6u);
    const CheckRow* passes = findRow(rows, "a passes through b");
    ASSERT_NE(passes, nullptr);
    EXPECT_TRUE(passes->pass) << passes->reason;
    EXPECT_EQ(findRow(rows, "a never passes through b")->reason, "on the other side at frame 19");
    EXPECT_EQ(findRow(rows, "a passes through c")->reason, "it never got to the other side");
    EXPECT_EQ(findRow(rows, "first time of impact a / b")->reason,
              "the CCD stage reported no time of impact for the pair");
    EXPECT_TRUE(findRow(rows, "c at rest")->pass);
    // a moves 0.1 m per frame: 0.3 m over frames 3..6, at 1 m/s.
    EXPECT_EQ(findRow(rows, "a at rest")->reason, "moved 0.3 m by frame 6; speed 1 m/s at frame 3");

    // With CCD the spheres stop just before their first contact (1.05 s, exact), short by the
    // stage's target gap (1e-3 to 2e-3 of the radius: 0.5 to 1 mm, 0.25 to 0.5 ms at 2 m/s),
    // and bounce apart.
    std::string text = kTwoSpheres;
    text.replace(text.find("frames: 25}"), 11, "frames: 25, ccd: conservative_advancement}");
    const engine::Scene on = parse(text +
                                   "expect:\n"
                                   "  tunnelling:\n"
                                   "    - {a: a, b: b, passes: false}\n"
                                   "  toi:\n"
                                   "    - {a: a, b: b, time: 1.05, tolerance: 5e-4}\n"
                                   "    - {a: b, b: a, time: 1.0, tolerance: 0.01}\n"
                                   "    - {a: a, b: b, time: 1.2, tolerance: 0.1}\n"
                                   "  energy_rise_max: 0\n"
                                   "  energy_drift_max: 1e-12\n");
    rows = checkScene(on, 25, dir);
    ASSERT_EQ(rows.size(), 6u);
    for (const char* good : {"a never passes", "in [1.0495, 1.05]", "energy rise", "drift"}) {
        const CheckRow* r = findRow(rows, good);
        ASSERT_NE(r, nullptr) << good;
        EXPECT_TRUE(r->pass) << good << ": " << r->reason;
    }
    EXPECT_NE(findRow(rows, "b / a in [0.99, 1]")->reason.find("later than the contact"),
              std::string::npos);
    EXPECT_NE(findRow(rows, "a / b in [1.1, 1.2]")->reason.find("too early"), std::string::npos);

    // Gravity with explicit Euler gains energy at every step.
    text = kTwoSpheres;
    text.replace(text.find("frames: 25}"), 11,
                 "frames: 25, gravity: [0, -9.81, 0], integrator: explicit_euler}");
    rows = checkScene(parse(text + "expect:\n  energy_rise_max: 1e-6\n"), 25, dir);
    ASSERT_EQ(rows.size(), 1u);
    EXPECT_FALSE(rows[0].pass);
    EXPECT_EQ(rows[0].reason.rfind("energy rose by ", 0), 0u) << rows[0].reason;
    fs::remove_all(dir);
}

TEST(Check, ShortRunsAndMissingSectionsFail) {
    const fs::path dir = checkDir("short");
    std::vector<CheckRow> rows = checkScene(parse(kTwoSpheres), 25, dir);
    ASSERT_EQ(rows.size(), 1u);
    EXPECT_FALSE(rows[0].pass);
    EXPECT_EQ(rows[0].reason, "the scene has no 'expect:' section");
    // Expectations built in code with nothing in them: checking nothing is no pass.
    engine::Scene nothing = parse(kTwoSpheres);
    nothing.expect.present = true;
    rows = checkScene(nothing, 25, dir);
    ASSERT_EQ(rows.size(), 1u);
    EXPECT_FALSE(rows[0].pass);
    EXPECT_EQ(rows[0].reason, "states no expectation");

    rows = checkScene(parse(kTwoSpheres + "expect:\n  pairs:\n"
                                          "    - {a: a, b: b, frames: [11, 20], colliding: true}\n"
                                          "  colors:\n    - {frame: 15, present: [red]}\n"
                                          "  pause_dumps: [14]\n"),
                      12, dir);
    ASSERT_EQ(rows.size(), 3u);
    for (const CheckRow& r : rows) {
        EXPECT_FALSE(r.pass) << r.expectation;
        EXPECT_EQ(r.reason, "the run has only 12 frames") << r.expectation;
    }
    fs::remove_all(dir);
}

// `volume:` counts the colours of one volume alone. Two spheres on the diagonal (1, 1, 0): their
// 6-DOPs (boxes) overlap, their 26-DOPs are apart on the (1, 1, 0) slab, so the 6-DOP frame has
// yellow and the 26-DOP frame none, though the scene draws both; a wrong expectation fails.
TEST(Check, ColoursOfOneVolumeAlone) {
    const fs::path dir = checkDir("volume");
    const std::string diagonal =
        "world: {bounds: {min: [-4, -4, -4], max: [4, 4, 4]}, time_step: 0.1, frames: 2}\n"
        "output: {width: 160, height: 120, fps: 10}\n"
        "camera: {position: [0, 0, 9], look_at: [0, 0, 0]}\n"
        "draw: {volumes: [kdop6, kdop26], bodies: false, bounds: false, hud: false}\n"
        "bodies:\n"
        "  - {name: d, shape: sphere, radius: 0.8, position: [-0.6, -0.6, 0]}\n"
        "  - {name: e, shape: sphere, radius: 0.8, position: [0.6, 0.6, 0]}\n"
        "expect:\n"
        "  colors:\n"
        "    - {frame: 0, present: [green, yellow]}\n"
        "    - {frame: 0, volume: kdop6, present: [yellow], absent: [green]}\n"
        "    - {frame: 0, volume: kdop26, present: [green], absent: [yellow]}\n"
        "    - {frame: 1, volume: kdop26, present: [yellow]}\n";
    const std::vector<CheckRow> rows = checkScene(parse(diagonal), 2, dir);
    ASSERT_EQ(rows.size(), 4u);
    EXPECT_TRUE(rows[0].pass) << rows[0].expectation << ": " << rows[0].reason;
    EXPECT_EQ(rows[1].expectation, "colours yellow, no green at frame 0 (kdop6 only)");
    EXPECT_TRUE(rows[1].pass) << rows[1].reason;
    EXPECT_EQ(rows[2].expectation, "colours green, no yellow at frame 0 (kdop26 only)");
    EXPECT_TRUE(rows[2].pass) << rows[2].reason;
    EXPECT_FALSE(rows[3].pass);
    EXPECT_EQ(rows[3].reason.rfind("yellow: 0 pixels, need 20", 0), 0u) << rows[3].reason;
    fs::remove_all(dir);
}

TEST(Check, SameSceneSameRows) {
    const fs::path dir = checkDir("det");
    const engine::Scene scene = parse(kTwoSpheres +
                                      "expect:\n  energy_drift_max: 0\n"
                                      "  colors:\n    - {frame: 3, absent: [red]}\n");
    const std::vector<CheckRow> a = checkScene(scene, 25, dir);
    const std::vector<CheckRow> b = checkScene(scene, 25, dir);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].expectation, b[i].expectation);
        EXPECT_EQ(a[i].pass, b[i].pass);
        EXPECT_EQ(a[i].reason, b[i].reason);
    }
    fs::remove_all(dir);
}

// A chain's links are bodies with names: `toi`, `tunnelling` and `pairs` grade them as they are.
// The shipped arm (scenes/arm.yaml) with its expectations replaced: its tip first touches the
// plate at 0.16722176 s (derived independently in the scene's comment).
TEST(Check, ChainLinksAreGradedByTheExistingExpectations) {
    const fs::path dir = checkDir("chain");
    std::string arm = slurp(fs::path(CDLAB_SOURCE_DIR) / "scenes/arm.yaml");
    arm.erase(arm.find("expect:"));
    const std::string expect =
        "expect:\n"
        "  toi:\n"
        "    - {a: tip, b: plate, time: 0.16722176, tolerance: 5e-5}\n"
        "    - {a: plate, b: tip, time: 0.1671, tolerance: 1e-3}\n"
        "    - {a: tip, b: plate, time: 0.2, tolerance: 1e-3}\n"
        "    - {a: tip, b: post, time: 0.25, tolerance: 0.1}\n"
        "  tunnelling:\n"
        "    - {a: tip, b: plate, passes: false}\n"
        "    - {a: tip, b: plate, passes: true}\n";
    std::vector<CheckRow> rows = checkScene(parse(arm + expect), 60, dir);
    ASSERT_EQ(rows.size(), 6u);
    EXPECT_TRUE(findRow(rows, "tip / plate in [0.16717176, 0.16722176]")->pass);
    EXPECT_NE(findRow(rows, "plate / tip in [0.1661, 0.1671]")->reason.find("later than"),
              std::string::npos);
    EXPECT_NE(findRow(rows, "tip / plate in [0.199, 0.2]")->reason.find("too early"),
              std::string::npos);
    // The arm halts at the plate: it never reaches the post.
    EXPECT_EQ(findRow(rows, "tip / post")->reason,
              "the CCD stage reported no time of impact for the pair");
    EXPECT_TRUE(findRow(rows, "tip never passes through plate")->pass);
    EXPECT_EQ(findRow(rows, "tip passes through plate")->reason, "it never got to the other side");

    // With ccd off the tip's centre is on the other side at frame 11 and there is no event.
    std::string off = arm;
    const std::string ccd_on = "\n  ccd: conservative_advancement\n";
    off.replace(off.find(ccd_on), ccd_on.size(), "\n  ccd: off\n");
    rows = checkScene(parse(off + expect), 60, dir);
    EXPECT_EQ(findRow(rows, "tip never passes through plate")->reason,
              "on the other side at frame 11");
    EXPECT_TRUE(findRow(rows, "tip passes through plate")->pass);
    EXPECT_EQ(findRow(rows, "tip / plate in [0.16717176, 0.16722176]")->reason,
              "the CCD stage reported no time of impact for the pair");
    fs::remove_all(dir);
}

// --- through the binary ---

TEST(CheckCli, ExitCodesAndTable) {
    const fs::path work = checkDir("cli");
    const fs::path good = work / "good.yaml";
    const fs::path bad = work / "wrong.yaml";
    const fs::path broken = work / "broken.yaml";
    std::ofstream(good) << kTwoSpheres
                        << "expect:\n  pairs:\n"
                           "    - {a: a, b: b, frames: [11, 20], colliding: true}\n";
    std::ofstream(bad) << kTwoSpheres
                       << "expect:\n  pairs:\n"
                          "    - {a: a, b: b, frames: [9, 20], colliding: true}\n";
    std::ofstream(broken) << kTwoSpheres << "expect:\n  pairs:\n"
                          << "    - {a: a, b: zz, frames: 1, colliding: true}\n";
    const fs::path empty = work / "empty.yaml";
    std::ofstream(empty) << kTwoSpheres << "expect:\n";

    Result r = runCdlab("check " + good.string(), work);
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("pair a / b colliding at every frames 11..20  pass"), std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("1 scene, 1 expectations, 0 failed"), std::string::npos) << r.out;

    r = runCdlab("check " + good.string() + " " + bad.string(), work);
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_NE(r.out.find("FAIL    does not hold at frame 9"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("2 scenes, 2 expectations, 1 failed"), std::string::npos) << r.out;

    // A shorter run than the expectations need is a failure, not bad input.
    r = runCdlab("check --frames 5 " + good.string(), work);
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_NE(r.out.find("the run has only 5 frames"), std::string::npos) << r.out;

    // Bad input: nothing runs, the precise message, exit 2.
    r = runCdlab("check " + good.string() + " " + broken.string(), work);
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
    EXPECT_NE(r.err.find("broken.yaml:11:17: expect.pairs[0].b: no body is named 'zz'"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.out, "");
    // An `expect:` that states nothing would pass having checked nothing: bad input too.
    r = runCdlab("check " + good.string() + " " + empty.string(), work);
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
    EXPECT_NE(r.err.find("empty.yaml:9:1: expect: states no expectation (give at least one of: "
                         "min_bodies,"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.out, "");
    r = runCdlab("check --frames 0 " + good.string(), work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--frames: must be >= 1"), std::string::npos) << r.err;
    r = runCdlab("check", work);
    EXPECT_EQ(r.exit_code, 2);

    // --out keeps the pause dumps.
    const fs::path dumps = work / "dumps";
    std::ofstream(good, std::ios::app) << "  pause_dumps: [2]\n";
    r = runCdlab("check --out " + dumps.string() + " " + good.string(), work);
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_TRUE(fs::exists(dumps / "0_good" / "pause_2.png"));
    EXPECT_TRUE(fs::exists(dumps / "0_good" / "pause_2.json"));
    fs::remove_all(work);
}

}  // namespace
}  // namespace app
