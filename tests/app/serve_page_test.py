#!/usr/bin/python3
"""`cdlab serve`'s page driven in headless Chromium (WebDriver: Debian's chromium-driver and
python3-selenium), two tabs at once: press pause, step, toggle OBBs, switch the broad phase,
click a body in the picture; after each, the picture the page shows is the server's PNG of the
newest version byte for byte, and the page's state (frame, layers, broad phase, selection,
pairs by name) is the server's state.json; a click on a pair shows its history and seeks. One
tab is closed mid-stream; the other goes on. Then the session log, replayed by `cdlab run
--events`, gives every frame's PNG equal to the last picture the page showed of it.

    serve_page_test.py CDLAB SOURCE_DIR WORK_DIR

Exit 0 when every check holds; 1 with the failed checks listed otherwise.
"""
import base64
import json
import subprocess
import sys
import time
import urllib.parse

from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select, WebDriverWait

from page_test_tools import (Server, arguments, browser, check, click_picture, get, lone_body,
                             report, script_errors, server_state)


# The bytes of the picture the page shows, fetched by the page itself from its own src.
SHOWN_BYTES = """
const done = arguments[arguments.length - 1];
const img = document.getElementById('frame-view');
fetch(img.src).then(r => r.arrayBuffer()).then(b => {
  let s = ''; const u = new Uint8Array(b);
  for (let i = 0; i < u.length; i += 8192) s += String.fromCharCode.apply(null, u.subarray(i, i + 8192));
  done([img.src, btoa(s), img.complete && img.naturalWidth]);
}).catch(e => done(['', '', String(e)]));
"""


def settled(driver, url, what):
    """Waits until the page shows the server's newest picture, then checks it is that PNG."""
    s = server_state(url)
    version = s["session"]["version"]
    try:
        WebDriverWait(driver, 10).until(
            lambda d: d.find_element(By.ID, "frame-view").get_attribute("src")
            .endswith("version=%d" % version))
    except Exception:
        check(False, "%s: the page shows version %d (src %s)" % (
            what, version, driver.find_element(By.ID, "frame-view").get_attribute("src")))
        return s
    src, data, width = driver.execute_async_script(SHOWN_BYTES)
    served = get(url + "api/frame.png?version=%d" % version)[1]
    check(base64.b64decode(data) == served, "%s: the picture shown is the server's PNG" % what)
    check(width == PAGE["width"], "%s: the picture loaded (%s wide)" % (what, width))
    if not s["session"]["playing"]:
        SHOWN[s["frame"]] = served
    WebDriverWait(driver, 10).until(
        lambda d: d.find_element(By.ID, "seek").get_attribute("value") == str(s["frame"]))
    return s


def main():
    cdlab, source, work = arguments()
    server = Server([cdlab, "serve", str(source / "scenes" / "coursework.yaml"), "--port", "0",
                     "--out", str(work / "live")])
    drivers = []
    try:
        url = server.url
        if url is None:
            return
        drivers = [browser(1500, 1000), browser(1500, 1000)]
        for d in drivers:
            d.get(url)
        main_tab, other = drivers
        WebDriverWait(main_tab, 20).until(
            lambda d: d.find_element(By.ID, "frame-view").get_attribute("src"))
        PAGE.update(json.loads(
            main_tab.find_element(By.ID, "serve-data").get_attribute("textContent")))

        main_tab.find_element(By.ID, "cmd-pause").click()
        WebDriverWait(main_tab, 10).until(lambda d: not server_state(url)["session"]["playing"])
        s = settled(main_tab, url, "pause")
        check("PAUSED" in main_tab.find_element(By.ID, "hud").text, "pause: the HUD says PAUSED")
        paused_at = s["frame"]

        main_tab.find_element(By.ID, "cmd-step").click()
        WebDriverWait(main_tab, 10).until(lambda d: server_state(url)["frame"] == paused_at + 1)
        settled(main_tab, url, "step")

        box = main_tab.find_element(By.ID, "layer-obb")
        was = box.is_selected()
        box.click()
        WebDriverWait(main_tab, 10).until(
            lambda d: ("obb" in server_state(url)["session"]["layers"]) != was)
        s = settled(main_tab, url, "toggle obb")
        check(main_tab.find_element(By.ID, "layer-obb").is_selected() == ("obb" in s["session"]["layers"]),
              "toggle obb: the box shows the layer's state")

        Select(main_tab.find_element(By.ID, "broadphase")).select_by_value("hgrid")
        WebDriverWait(main_tab, 10).until(lambda d: server_state(url)["broadphase"] == "hgrid")
        s = settled(main_tab, url, "broad phase")

        # A body in the picture, clicked at the centre of its rectangle where it is the
        # smallest there: it becomes the selection, named in the page.
        target = lone_body(s["session"]["rects"], PAGE["width"], PAGE["height"])
        if check(target is not None, "some body is alone at its centre"):
            i, cx, cy = target
            name = s["bodies"][i]["name"]
            click_picture(main_tab, main_tab.find_element(By.ID, "frame-view"), cx, cy,
                          PAGE["width"], PAGE["height"])
            WebDriverWait(main_tab, 10).until(
                lambda d: server_state(url)["session"]["selected"] == name)
            settled(main_tab, url, "select")
            check(("selected: " + name) in main_tab.find_element(By.ID, "selected").text,
                  "select: the page names %s" % name)

        # The other tab follows what the first one did.
        settled(other, url, "the second tab")
        s = server_state(url)
        names = [b["name"] for b in s["bodies"]]
        shown = other.find_element(By.ID, "flagged-pairs").text
        for a, b in s["flagged_pairs"][:20]:
            check("%s \u2013 %s" % (names[a], names[b]) in shown,
                  "the second tab lists the flagged pair %s-%s by name" % (names[a], names[b]))

        # A click on a pair shows its history, the ranges /api/pair.json gives; a click on a
        # range seeks to its first frame.
        rows = other.find_elements(By.CSS_SELECTOR, "#flagged-pairs li.pair-row")
        if check(rows, "the flagged pairs are rows to click (%d pairs)" % len(s["flagged_pairs"])):
            a, b = [names[k] for k in s["flagged_pairs"][0]]
            rows[0].click()
            WebDriverWait(other, 10).until(
                lambda d: d.find_element(By.ID, "pair-history").is_displayed())
            shown = other.find_element(By.ID, "pair-history").text
            query = urllib.parse.urlencode({"a": a, "b": b})
            h = json.loads(get(url + "api/pair.json?" + query)[1])
            check("pair %s \u2013 %s" % (a, b) in shown, "the history names the pair: " + shown)
            buttons = other.find_elements(By.CSS_SELECTOR, "#pair-history .flagged-ranges button")
            texts = [("%d" % f if f == l else "%d\u2013%d" % (f, l)) for f, l in h["flagged"]]
            check([x.text for x in buttons] == texts,
                  "the page's ranges %s are the API's %s" % ([x.text for x in buttons], texts))
            if buttons:
                buttons[0].click()
                WebDriverWait(other, 10).until(
                    lambda d: server_state(url)["frame"] == h["flagged"][0][0])
                settled(other, url, "seek from a pair's history")

        # Playing, one tab closed mid-stream: the other keeps receiving pictures.
        played_from = server_state(url)["frame"]
        main_tab.find_element(By.ID, "cmd-play").click()
        time.sleep(0.5)
        other.quit()
        drivers.remove(other)
        before = server_state(url)["session"]["version"]
        time.sleep(1.0)
        check(server_state(url)["session"]["version"] > before + 5, "playing on after a tab closed")
        main_tab.find_element(By.ID, "cmd-pause").click()
        WebDriverWait(main_tab, 10).until(lambda d: not server_state(url)["session"]["playing"])
        # The frames played through were shown again, playing: their last pictures are those.
        for frame in [f for f in SHOWN if f >= played_from]:
            del SHOWN[frame]
        settled(main_tab, url, "pause again")
        # Back a frame and then ten, paused, and an orbit there: more frames' last pictures.
        for button, what in [("cmd-back", "back 1"), ("cmd-back10", "back 10"),
                             ("cam-left", "orbit")]:
            version = server_state(url)["session"]["version"]
            main_tab.find_element(By.ID, button).click()
            WebDriverWait(main_tab, 10).until(
                lambda d: server_state(url)["session"]["version"] > version)
            settled(main_tab, url, what)
        errors = script_errors(main_tab)
        check(not errors, "no script error in the browser: %s" % errors)
    finally:
        for d in drivers:
            d.quit()
        server.stop()

    # The session log replayed by `cdlab run --events`: every frame's PNG is the last picture
    # the page showed of it.
    replay = work / "replay"
    r = subprocess.run([cdlab, "run", str(source / "scenes" / "coursework.yaml"), "--events",
                        str(work / "live" / "session.yaml"), "--no-hud-timing", "--no-video",
                        "--quiet", "--out", str(replay)], capture_output=True, text=True)
    if check(r.returncode == 0, "replay: exit %d: %s" % (r.returncode, r.stderr)):
        for frame, png in sorted(SHOWN.items()):
            written = replay / ("frame_%05d.png" % frame)
            check(written.is_file() and written.read_bytes() == png,
                  "frame %d: the page's last picture equals the replay's %s" % (frame, written.name))
        check(len(SHOWN) >= 3, "pictures compared with the replay: %d" % len(SHOWN))


PAGE = {}  # the page's own data: the picture's size, the layers, the broad phases
SHOWN = {}  # frame -> the last picture the page showed of it while paused

if __name__ == "__main__":
    main()
    sys.exit(report())
