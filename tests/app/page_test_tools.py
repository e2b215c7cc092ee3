"""What the Python tests of cdlab's pages and server share: checks collected and reported, the
command line ctest gives them, HTTP over urllib, a `cdlab serve` process, and headless Chromium
(Debian's chromium and chromium-driver through python3-selenium) with the picture-click helpers.

Imported by the tests beside it: run as `/usr/bin/python3 tests/app/X_test.py ...`, a script's
own folder is first on sys.path. Selenium is imported only when a browser is started, so the
HTTP-only tests do not need it.
"""
import json
import shutil
import signal
import subprocess
import sys
import urllib.error
import urllib.request
from pathlib import Path

failures = []  # what each failed check said, in order


def check(condition, what):
    """Records `what` as a failure unless `condition` holds; returns `condition`."""
    if not condition:
        failures.append(what)
    return condition


def report(prefix="FAILED:"):
    """Prints each failed check on a line after `prefix`; the exit status: 1 if any failed."""
    for f in failures:
        print(prefix, f)
    return 1 if failures else 0


def arguments():
    """CDLAB SOURCE_DIR WORK_DIR from the command line, WORK_DIR made anew and empty."""
    cdlab, source, work = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    return cdlab, source, work


def get(address):
    """GET: (status, body bytes, headers); an HTTP error status is returned, not raised."""
    try:
        with urllib.request.urlopen(address, timeout=20) as r:
            return r.status, r.read(), dict(r.headers)
    except urllib.error.HTTPError as e:
        return e.code, e.read(), dict(e.headers)


def post(url, body):
    """POSTs a command to the server at `url`, bytes as they are, else as JSON: (status, answer
    parsed)."""
    data = body if isinstance(body, bytes) else json.dumps(body).encode()
    request = urllib.request.Request(url + "api/command", data=data, method="POST")
    try:
        with urllib.request.urlopen(request, timeout=20) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read())


def server_state(url):
    """The server's GET api/state.json, parsed."""
    return json.loads(get(url + "api/state.json")[1])


class Server:
    """A `cdlab serve` process (give it --port 0): its address read from the line it prints
    first, checked; stopped by SIGTERM, checked to exit 0 within 20 s. Use it in a `with`:
    the server is stopped on the way out if `stop()` was not called before."""

    def __init__(self, args):
        self.process = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                        text=True)
        first = self.process.stdout.readline()
        self.url = first.split()[2] if first.startswith("cdlab serve: http://127.0.0.1:") else None
        check(self.url is not None,
              "URL line: %r %s" % (first, self.process.stderr.read()
                                   if self.process.poll() is not None else ""))
        self.output = None

    def __enter__(self):
        return self

    def __exit__(self, *exception):
        self.stop()

    def stop(self):
        """Stops the server once; its (stdout, stderr) after the URL line."""
        if self.output is None:
            self.process.send_signal(signal.SIGTERM)  # nothing if it has exited already
            try:
                self.output = self.process.communicate(timeout=20)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.output = self.process.communicate()
                check(False, "the server stops on SIGTERM")
                return self.output
            check(self.process.returncode == 0, "SIGTERM: exit %s, stderr %s"
                  % (self.process.returncode, self.output[1]))
        return self.output


def browser(width, height, hide_scrollbars=False):
    """Headless Chromium through ChromeDriver, a width x height window at scale 1, keeping the
    page's console log for `script_errors`."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for flag in ("--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                 "--window-size=%d,%d" % (width, height), "--force-device-scale-factor=1"):
        options.add_argument(flag)
    if hide_scrollbars:
        options.add_argument("--hide-scrollbars")
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)


def script_errors(driver):
    """The SEVERE messages in the browser's console log (script errors, failed loads)."""
    return [e["message"] for e in driver.get_log("browser") if e["level"] == "SEVERE"]


def body_at(rects, x, y):
    """The body the page picks at picture pixel (x, y): the smallest rectangle holding it
    (the first of equal ones); -1 if none does. rects[i] is body i's [x0, y0, x1, y1] or None."""
    best, area = -1, float("inf")
    for i, r in enumerate(rects):
        if r is None or not (r[0] <= x <= r[2] and r[1] <= y <= r[3]):
            continue
        a = (r[2] - r[0]) * (r[3] - r[1])
        if a < area:
            best, area = i, a
    return best


def lone_body(rects, width=None, height=None):
    """The first body the page picks at its own rectangle's centre, as (i, x, y), or None.
    With the picture's width and height, only bodies wholly inside the picture."""
    for i, r in enumerate(rects):
        if r is None:
            continue
        if width is not None and (r[0] < 0 or r[1] < 0 or r[2] > width or r[3] > height):
            continue
        cx, cy = (r[0] + r[2]) / 2, (r[1] + r[3]) / 2
        if body_at(rects, cx, cy) == i:
            return i, cx, cy
    return None


def click_picture(driver, img, x, y, width, height):
    """Clicks the <img> at pixel (x, y) of its width x height picture, however it is scaled."""
    from selenium.webdriver.common.action_chains import ActionChains

    size = img.size
    ActionChains(driver).move_to_element_with_offset(
        img, int(x * size["width"] / width - size["width"] / 2),
        int(y * size["height"] / height - size["height"] / 2)).click().perform()
