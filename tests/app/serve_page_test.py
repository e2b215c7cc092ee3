#!/usr/bin/python3
"""`cdlab serve`'s page driven in headless Chromium (WebDriver: Debian's chromium-driver and
python3-selenium), two tabs at once: press pause, step, toggle OBBs, switch the broad phase,
click a body in the picture; after each, the picture the page shows is the server's PNG of the
newest version byte for byte, and the page's state (frame, layers, broad phase, selection,
pairs by name) is the server's state.json. One tab is closed mid-stream; the other goes on.

    serve_page_test.py CDLAB SOURCE_DIR WORK_DIR

Exit 0 when every check holds; 1 with the failed checks listed otherwise.
"""
import base64
import json
import shutil
import signal
import subprocess
import sys
import time
import urllib.parse
import urllib.request
from pathlib import Path

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select, WebDriverWait

failures = []


def check(condition, what):
    if not condition:
        failures.append(what)
    return condition


def browser():
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for flag in ("--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                 "--window-size=1500,1000", "--force-device-scale-factor=1"):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)


def get(address):
    with urllib.request.urlopen(address, timeout=20) as r:
        return r.read()


def state(url):
    return json.loads(get(url + "api/state.json"))


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
    s = state(url)
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
    served = get(url + "api/frame.png?version=%d" % version)
    check(base64.b64decode(data) == served, "%s: the picture shown is the server's PNG" % what)
    check(width == PAGE["width"], "%s: the picture loaded (%s wide)" % (what, width))
    WebDriverWait(driver, 10).until(
        lambda d: d.find_element(By.ID, "seek").get_attribute("value") == str(s["frame"]))
    return s


def main():
    cdlab, source, work = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    server = subprocess.Popen(
        [cdlab, "serve", str(source / "scenes" / "coursework.yaml"), "--port", "0",
         "--out", str(work / "live")], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    drivers = []
    try:
        first = server.stdout.readline()
        if not check(first.startswith("cdlab serve: http://"), "URL line: " + first):
            return
        url = first.split()[2]
        drivers = [browser(), browser()]
        for d in drivers:
            d.get(url)
        main_tab, other = drivers
        WebDriverWait(main_tab, 20).until(
            lambda d: d.find_element(By.ID, "frame-view").get_attribute("src"))
        PAGE.update(json.loads(
            main_tab.find_element(By.ID, "serve-data").get_attribute("textContent")))

        main_tab.find_element(By.ID, "cmd-pause").click()
        WebDriverWait(main_tab, 10).until(lambda d: not state(url)["session"]["playing"])
        s = settled(main_tab, url, "pause")
        check("PAUSED" in main_tab.find_element(By.ID, "hud").text, "pause: the HUD says PAUSED")
        paused_at = s["frame"]

        main_tab.find_element(By.ID, "cmd-step").click()
        WebDriverWait(main_tab, 10).until(lambda d: state(url)["frame"] == paused_at + 1)
        settled(main_tab, url, "step")

        box = main_tab.find_element(By.ID, "layer-obb")
        was = box.is_selected()
        box.click()
        WebDriverWait(main_tab, 10).until(
            lambda d: ("obb" in state(url)["session"]["layers"]) != was)
        s = settled(main_tab, url, "toggle obb")
        check(main_tab.find_element(By.ID, "layer-obb").is_selected() == ("obb" in s["session"]["layers"]),
              "toggle obb: the box shows the layer's state")

        Select(main_tab.find_element(By.ID, "broadphase")).select_by_value("hgrid")
        WebDriverWait(main_tab, 10).until(lambda d: state(url)["broadphase"] == "hgrid")
        s = settled(main_tab, url, "broad phase")

        # A body in the picture, clicked at the centre of its rectangle where it is the
        # smallest there: it becomes the selection, named in the page.
        img = main_tab.find_element(By.ID, "frame-view")
        size = img.size
        target = None
        rects = s["session"]["rects"]
        for i, r in enumerate(rects):
            if r is None or r[0] < 0 or r[1] < 0 or r[2] > PAGE["width"] or r[3] > PAGE["height"]:
                continue
            cx, cy = (r[0] + r[2]) / 2, (r[1] + r[3]) / 2
            holding = [j for j, q in enumerate(rects)
                       if q and q[0] <= cx <= q[2] and q[1] <= cy <= q[3]]
            if min(holding, key=lambda j: (rects[j][2] - rects[j][0]) * (rects[j][3] - rects[j][1])) == i:
                target = (i, cx, cy)
                break
        if check(target is not None, "some body is alone at its centre"):
            i, cx, cy = target
            name = s["bodies"][i]["name"]
            ActionChains(main_tab).move_to_element_with_offset(
                img, int(cx * size["width"] / PAGE["width"] - size["width"] / 2),
                int(cy * size["height"] / PAGE["height"] - size["height"] / 2)).click().perform()
            WebDriverWait(main_tab, 10).until(lambda d: state(url)["session"]["selected"] == name)
            settled(main_tab, url, "select")
            check(("selected: " + name) in main_tab.find_element(By.ID, "selected").text,
                  "select: the page names %s" % name)

        # The other tab follows what the first one did.
        settled(other, url, "the second tab")
        s = state(url)
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
            h = json.loads(get(url + "api/pair.json?" + query))
            check("pair %s \u2013 %s" % (a, b) in shown, "the history names the pair: " + shown)
            buttons = other.find_elements(By.CSS_SELECTOR, "#pair-history .flagged-ranges button")
            texts = [("%d" % f if f == l else "%d\u2013%d" % (f, l)) for f, l in h["flagged"]]
            check([x.text for x in buttons] == texts,
                  "the page's ranges %s are the API's %s" % ([x.text for x in buttons], texts))
            if buttons:
                buttons[0].click()
                WebDriverWait(other, 10).until(
                    lambda d: state(url)["frame"] == h["flagged"][0][0])
                settled(other, url, "seek from a pair's history")

        # Playing, one tab closed mid-stream: the other keeps receiving pictures.
        main_tab.find_element(By.ID, "cmd-play").click()
        time.sleep(0.5)
        other.quit()
        drivers.remove(other)
        before = state(url)["session"]["version"]
        time.sleep(1.0)
        check(state(url)["session"]["version"] > before + 5, "playing on after a tab closed")
        main_tab.find_element(By.ID, "cmd-pause").click()
        WebDriverWait(main_tab, 10).until(lambda d: not state(url)["session"]["playing"])
        settled(main_tab, url, "pause again")
        errors = [e["message"] for e in main_tab.get_log("browser") if e["level"] == "SEVERE"]
        check(not errors, "no script error in the browser: %s" % errors)
    finally:
        for d in drivers:
            d.quit()
        server.send_signal(signal.SIGTERM)
        try:
            server.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            server.kill()
            check(False, "the server stops on SIGTERM")
    check(server.returncode == 0, "the server exits 0 (%s)" % server.returncode)


PAGE = {}  # the page's own data: the picture's size, the layers, the broad phases

if __name__ == "__main__":
    main()
    for f in failures:
        print("FAILED:", f)
    sys.exit(1 if failures else 0)
