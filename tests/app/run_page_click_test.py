#!/usr/bin/python3
"""A run's index.html driven by a user in headless Chromium (WebDriver: Debian's chromium-driver
and python3-selenium): click each pause's pairs, a body's row and a body in the picture, and check
what the page shows against pause_F.json, with no script error in the browser's log.

    run_page_click_test.py CDLAB SOURCE_DIR WORK_DIR

Exit 0 when every check holds; 1 with the failed checks listed otherwise.
"""
import json
import shutil
import subprocess
import sys

from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import WebDriverWait

from page_test_tools import (arguments, browser, check, click_picture, lone_body, report,
                             script_errors)


def detail_text(article):
    return article.find_element(By.CSS_SELECTOR, "div.detail").text


def highlighted(article):
    return sorted(int(r.get_attribute("data-body"))
                  for r in article.find_elements(By.CSS_SELECTOR, "tr.highlight"))


def shows(text, body_id, name):
    """Whether a detail's text holds the body's heading line ("body" then "ID NAME (SHAPE)")."""
    return ("\n%d %s (" % (body_id, name)) in ("\n" + text)


def main():
    cdlab, source, work = arguments()
    out = work / "out"
    # The coursework with a k-DOP drawn: each body's detail then lists its 14-DOP too.
    run = subprocess.run(
        [cdlab, "run", str(source / "scenes" / "coursework.yaml"), "--html", "--no-video",
         "--quiet", "--frames", "45", "--pause-at", "20", "--pause-at", "41",
         "--set", "draw.volumes=[sphere, aabb, obb, kdop14]", "--out", str(out)],
        capture_output=True, text=True, timeout=300)
    if run.returncode != 0:
        print("cdlab run failed:", run.returncode, run.stderr)
        return 1

    driver = browser(1280, 900, hide_scrollbars=True)
    try:
        driver.get((out / "index.html").resolve().as_uri())
        WebDriverWait(driver, 30).until(
            lambda d: d.find_element(By.TAG_NAME, "body").get_attribute("data-rendered") == "1")
        data = json.loads(driver.find_element(By.ID, "run-data").get_attribute("textContent"))
        clicked_pairs = 0
        for pause in data["pauses"]:
            frame = pause["frame"]
            dump = json.loads((out / ("pause_%d.json" % frame)).read_text())
            names = {b["id"]: b["name"] for b in dump["bodies"]}
            article = driver.find_element(By.ID, "pause-%d" % frame)
            buttons = article.find_elements(By.CSS_SELECTOR, "button.pair")
            pairs = dump["colliding_pairs"] + dump["flagged_pairs"]
            check([b.text for b in buttons] ==
                  ["%s\u2013%s" % (names[a], names[b]) for a, b in pairs],
                  "frame %d: the pair buttons are named by their bodies, in the dump's order" % frame)
            for button, (a, b) in zip(buttons, pairs):
                driver.execute_script("arguments[0].scrollIntoView({block: 'center'})", button)
                button.click()
                clicked_pairs += 1
                text = detail_text(article)
                check(shows(text, a, names[a]) and shows(text, b, names[b]),
                      "frame %d, pair %s-%s: the detail shows both bodies" % (frame, a, b))
                check(text.count("14-DOP") == 2,
                      "frame %d, pair %s-%s: each body's 14-DOP is listed" % (frame, a, b))
                check(highlighted(article) == sorted([a, b]),
                      "frame %d, pair %s-%s: both rows highlighted" % (frame, a, b))
                check(len(article.find_elements(By.CSS_SELECTOR, "div.outline")) == 2,
                      "frame %d, pair %s-%s: both bodies outlined in the picture" % (frame, a, b))

            # A body's row, clicked: its detail, pinned.
            row = article.find_elements(By.CSS_SELECTOR, "tr.body")[3]
            driver.execute_script("arguments[0].scrollIntoView({block: 'center'})", row)
            row.click()
            check(shows(detail_text(article), 3, names[3]) and highlighted(article) == [3],
                  "frame %d: a clicked row shows that body (%s; %s)" % (frame, highlighted(article), detail_text(article)[:80]))

            # A body in the picture, clicked at its rectangle's centre: the body the page's rule
            # picks there (the smallest rectangle holding the point) is the one shown.
            img = article.find_element(By.CSS_SELECTOR, "div.picture img")
            driver.execute_script("arguments[0].scrollIntoView({block: 'center'})", img)
            target = lone_body(pause["rects"])
            if check(target is not None, "frame %d: some body is alone at its centre" % frame):
                i, cx, cy = target
                click_picture(driver, img, cx, cy, data["width"], data["height"])
                check(shows(detail_text(article), i, names[i]) and
                      highlighted(article) == [i],
                      "frame %d: clicking body %d in the picture shows it" % (frame, i))
        check(clicked_pairs > 0, "the run's pauses had pairs to click")
        errors = script_errors(driver)
        check(not errors, "no script error in the browser: %s" % errors)
        print("clicked %d pairs over %d pauses" % (clicked_pairs, len(data["pauses"])))
    finally:
        driver.quit()

    status = report()
    if status == 0:
        shutil.rmtree(work, ignore_errors=True)
    return status


if __name__ == "__main__":
    sys.exit(main())
