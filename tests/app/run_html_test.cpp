// tests/app/run_html_test.cpp -- `cdlab run --html`: index.html, loaded in headless Chromium,
// shows the video, a drawn timeline of the run's pairs, and the pause picture's bodies; a video
// that cannot be loaded, a run without one and a run that failed say so plainly.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "browser.h"
#include "cli_run.h"
#include "html_page.h"
#include "render/image.h"

namespace {

namespace fs = std::filesystem;
using namespace cdlab_test;

// Two spheres pushed into each other (a confirmed pair from the first frame), a turned box whose
// AABB overlaps a ball's but not the ball (a flagged pair, not confirmed), a capsule apart; the
// first two bodies' names are HTML and a closing script tag, which the page
// must show as text.
const char* kSceneText = R"(world:
  bounds: {min: [-4, -3, -3], max: [4, 3, 3]}
  time_step: 0.02
  steps_per_frame: 1
  frames: 12
broadphase: sap
output: {width: 320, height: 180, fps: 10}
camera: {position: [0, 2, 12], look_at: [0, 0, 0]}
bodies:
  - name: "</script><script>document.title='broken'</script>"
    shape: sphere
    radius: 0.5
    position: [-0.45, 0, 0]
    velocity: [1, 0, 0]
  - name: "<b>right</b> & co"
    shape: sphere
    radius: 0.5
    position: [0.45, 0, 0]
    velocity: [-1, 0, 0]
  - {name: crate, shape: box, half_extents: [0.5, 0.5, 0.5], euler_deg: [0, 0, 45],
     position: [-2.5, 1.5, 0]}
  - {name: ball, shape: sphere, radius: 0.3, position: [-1.6, 2.4, 0]}
  - {name: pill, shape: capsule, radius: 0.3, half_height: 0.5, position: [2.5, 1.5, 0]}
)";

fs::path writeScene(const fs::path& dir) {
    const fs::path file = dir / "html_run.yaml";
    std::ofstream(file) << kSceneText;
    return file;
}

// The JSON a page embeds in <script type="application/json" id=ID>.
nlohmann::json embeddedJson(const std::string& html, const std::string& id) {
    const std::string open = "<script type=\"application/json\" id=\"" + id + "\">";
    const std::size_t start = html.find(open);
    if (start == std::string::npos) return nullptr;
    const std::size_t end = html.find("</script>", start);
    return nlohmann::json::parse(html.substr(start + open.size(), end - start - open.size()));
}

// One column of a CSV file with a header row, as numbers.
std::vector<long long> csvColumn(const fs::path& file, const std::string& name) {
    std::ifstream f(file);
    std::string line;
    std::getline(f, line);
    int column = -1, k = 0;
    std::stringstream header(line);
    for (std::string cell; std::getline(header, cell, ','); ++k) {
        if (cell == name) column = k;
    }
    std::vector<long long> values;
    while (std::getline(f, line)) {
        std::stringstream row(line);
        std::string cell;
        for (int i = 0; i <= column; ++i) std::getline(row, cell, ',');
        values.push_back(std::stoll(cell));
    }
    return values;
}

}  // namespace

// The page of a run with a video and a pause: the player has the run's video and loads it, the
// charts were drawn (the timeline's lines are on screen, in the plot area), the pause lists
// every body of pause_3.json, hostile names stay text; the timeline is the --stats CSV's.
// Then the video is deleted: the same page says "no video" instead of showing a dead player.
TEST(RunHtml, PageShowsVideoTimelineAndPauseBodies) {
    ASSERT_FALSE(chromiumBinary().empty()) << kNoChromium;
    if (!haveFfprobe()) GTEST_SKIP() << "ffmpeg not on PATH (Debian package ffmpeg)";
    const fs::path work = tempDir("cdlab_html_", "run");
    const fs::path out = work / "out";
    const CliResult r =
        runCdlab("run " + writeScene(work).string() + " --html --pause-at 3 --quiet --stats " +
                     (work / "stats.csv").string() + " --out " + out.string(),
                 work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string html = slurp(out / "index.html");
    ASSERT_FALSE(html.empty());
    EXPECT_EQ(html.find("<script>document.title"), std::string::npos);

    const nlohmann::json data = embeddedJson(html, "run-data");
    ASSERT_TRUE(data.is_object());
    const std::vector<long long> flagged = data["timeline"]["flagged"];
    const std::vector<long long> colliding = data["timeline"]["colliding"];
    EXPECT_EQ(flagged, csvColumn(work / "stats.csv", "flagged"));
    EXPECT_EQ(colliding, csvColumn(work / "stats.csv", "colliding"));
    ASSERT_EQ(colliding.size(), 12u);
    EXPECT_GT(colliding[0], 0);
    EXPECT_GT(flagged[0], colliding[0]);

    const std::string dom = runChromium(out / "index.html", "", "--dump-dom", work);
    ASSERT_NE(dom.find("<body data-rendered=\"1\""), std::string::npos)
        << "the page's script did not finish: " << slurp(work / "chromium.log");
    EXPECT_NE(dom.find("<title>cdlab run: html_run</title>"), std::string::npos);
    const std::string video = startTag(dom, "video");
    EXPECT_EQ(attribute(video, "src"), "html_run.mp4") << video;
    EXPECT_NE(attribute(video, "data-duration"), "") << "the video did not load: " << video;
    EXPECT_NE(startTag(dom, "no-video").find("hidden"), std::string::npos);
    const std::string pairs_chart = startTag(dom, "pairs-chart");
    EXPECT_EQ(attribute(pairs_chart, "data-rendered"), "1") << pairs_chart;
    EXPECT_EQ(attribute(startTag(dom, "stages-chart"), "data-rendered"), "1");
    const nlohmann::json pause = nlohmann::json::parse(slurp(out / "pause_3.json"));
    EXPECT_EQ(countOf(dom, "<tr class=\"body state-"), int(pause["bodies"].size()));
    EXPECT_NE(dom.find("<td>&lt;/script&gt;&lt;script&gt;document.title='broken'&lt;/script&gt;"
                       "</td>"),
              std::string::npos);
    EXPECT_NE(dom.find("<td>&lt;b&gt;right&lt;/b&gt; &amp; co</td>"), std::string::npos);

    // On screen: the flagged (amber) and confirmed (red) lines inside the plot area.
    const fs::path shot = work / "run.png";
    runChromium(out / "index.html", "", "--screenshot=" + shot.string(), work);
    ASSERT_TRUE(fs::exists(shot)) << slurp(work / "chromium.log");
    const render::Image image = render::readPng(shot);
    const std::string rect = attribute(pairs_chart, "data-rect");
    EXPECT_GT(pixelsInRect(image, rect, {0xe6, 0xb0, 0x00}), 200) << rect;
    EXPECT_GT(pixelsInRect(image, rect, {0xdc, 0x28, 0x28}), 200) << rect;

    fs::remove(out / "html_run.mp4");
    const std::string missing = runChromium(out / "index.html", "", "--dump-dom", work);
    const std::string message = startTag(missing, "no-video");
    EXPECT_EQ(message.find("hidden"), std::string::npos) << message;
    EXPECT_NE(missing.find("no video: cannot load html_run.mp4"), std::string::npos) << message;
    EXPECT_NE(startTag(missing, "video").find("hidden"), std::string::npos);
    fs::remove_all(work);
}

// Without a video the page says why in place of the player and shows the frames' PNGs
// instead (the timeline's cursor picks which); a later run into the same folder
// that fails (its encoder dies) leaves no index.html behind, not even the earlier one.
TEST(RunHtml, NoVideoIsSaidAndAFailedRunLeavesNoPage) {
    const fs::path work = tempDir("cdlab_html_", "failed");
    const fs::path out = work / "out";
    const std::string scene = writeScene(work).string();
    const CliResult ok =
        runCdlab("run " + scene + " --html --no-video --quiet --out " + out.string(), work);
    ASSERT_EQ(ok.exit_code, 0) << ok.err;
    const std::string html = slurp(out / "index.html");
    EXPECT_NE(html.find("id=\"no-video\">no video: the run was made with --no-video</p>"),
              std::string::npos);
    EXPECT_EQ(html.find("<video"), std::string::npos);
    EXPECT_NE(html.find("<img id=\"frame-view\" alt=\"the frame at the cursor\" "
                        "src=\"frame_00000.png\">"),
              std::string::npos);

    const fs::path bin = work / "bin";
    fs::create_directories(bin);
    std::ofstream(bin / "ffmpeg") << "#!/bin/sh\nexit 3\n";
    fs::permissions(bin / "ffmpeg", fs::perms::owner_all);
    const CliResult failed = runCdlab("run " + scene + " --html --quiet --out " + out.string(),
                                      work, "PATH=" + bin.string() + ":/usr/bin:/bin");
    EXPECT_EQ(failed.exit_code, 1) << failed.err;
    EXPECT_FALSE(fs::exists(out / "index.html"));
    EXPECT_FALSE(fs::exists(out / "summary.json"));
    fs::remove_all(work);
}

// A scene drawing k-DOPs: the page's pause table has a column per k-DOP drawn, named like the
// legend ("6-DOP", "26-DOP"), holding each body's state of that k-DOP from the pause dump.
TEST(RunHtml, PauseTableListsTheKdopsDrawn) {
    ASSERT_FALSE(chromiumBinary().empty()) << kNoChromium;
    const fs::path work = tempDir("cdlab_html_", "kdop");
    std::string text = kSceneText;
    const std::string bodies = "bodies:\n";
    text.insert(text.find(bodies), "draw: {volumes: [kdop6, kdop26]}\n");
    const fs::path scene = work / "kdops.yaml";
    std::ofstream(scene) << text;
    const fs::path out = work / "out";
    const CliResult r = runCdlab("run " + scene.string() +
                                     " --html --no-video --frames 2 --pause-at 1 --quiet --out " +
                                     out.string(),
                                 work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json pause = nlohmann::json::parse(slurp(out / "pause_1.json"));
    const std::string dom = runChromium(out / "index.html", "", "--dump-dom", work);
    ASSERT_NE(dom.find("<body data-rendered=\"1\""), std::string::npos)
        << "the page's script did not finish: " << slurp(work / "chromium.log");
    EXPECT_NE(dom.find("<th>OBB</th><th>6-DOP</th><th>26-DOP</th></tr>"), std::string::npos);
    EXPECT_EQ(dom.find("<th>14-DOP</th>"), std::string::npos);
    // Each body's row ends with its 6-DOP and 26-DOP states.
    for (const nlohmann::json& b : pause["bodies"]) {
        const std::string cells = "<td>" + b["volume_states"]["obb"].get<std::string>() +
                                  "</td><td>" + b["volume_states"]["kdop6"].get<std::string>() +
                                  "</td><td>" + b["volume_states"]["kdop26"].get<std::string>() +
                                  "</td></tr>";
        EXPECT_NE(dom.find(cells), std::string::npos) << cells;
    }
    fs::remove_all(work);
}

// Names are data: escaped in the page's text, and unable to end the JSON element, whose text
// still parses to the same strings.
TEST(HtmlPage, EscapesTextAndEmbedsJsonThatCannotCloseItsElement) {
    EXPECT_EQ(app::html::escape("<a href=\"x\">'&'</a>"),
              "&lt;a href=&quot;x&quot;&gt;&#39;&amp;&#39;&lt;/a&gt;");
    const nlohmann::json value = {{"name", "</script><!-- & -->"}};
    const std::string element = app::html::jsonScript("d", value.dump());
    const std::string open = "<script type=\"application/json\" id=\"d\">";
    ASSERT_EQ(element.rfind(open, 0), 0u);
    const std::string text = element.substr(open.size(), element.find("</script>") - open.size());
    EXPECT_EQ(element.find("</script>"), element.size() - 10);
    EXPECT_EQ(text.find('<'), std::string::npos);
    EXPECT_EQ(nlohmann::json::parse(text), value);
    EXPECT_EQ(app::html::urlPath("a b/c#1?.mp4"), "a%20b/c%231%3F.mp4");
    EXPECT_EQ(app::html::urlPath("/tmp/v.mp4"), "file:///tmp/v.mp4");
}
