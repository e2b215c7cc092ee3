#!/usr/bin/python3
"""`cdlab serve` driven over its HTTP API as a script or curl would: commands applied and
answered with their frames, the pictures and states they change, bad requests refused with a
message naming what is wrong, a watcher long-polling beside the commands, a client that hangs
up mid-request, SIGTERM with the session log complete on disk; then the log replayed by
`cdlab run --events` and every picture the server showed last of a frame compared with that
frame's PNG, byte for byte.

    serve_api_test.py CDLAB SOURCE_DIR WORK_DIR

Exit 0 when every check holds; 1 with the failed checks listed otherwise.
"""
import json
import socket
import subprocess
import sys
import threading
import time

from page_test_tools import Server, arguments, check, get, post, report, server_state


def main():
    cdlab, source, work = arguments()
    scene = str(source / "scenes" / "coursework.yaml")
    live = work / "live"
    log = work / "session.yaml"
    with Server([cdlab, "serve", scene, "--port", "0", "--paused", "--out", str(live),
                 "--session", str(log)]) as server:
        url = server.url
        if url is None:
            return
        exercise(url, live, work)
        shown = SHOWN
        before_stop = get(url + "api/session.yaml")[1].decode()
        out, err = server.stop()
        check("stopped; session log" in out, "the stop is said: " + out)
        check(log.read_text() == before_stop,
              "the log on disk is the log the server gave last:\n%s\n---\n%s"
              % (log.read_text(), before_stop))

    replay = work / "replay"
    r = subprocess.run([cdlab, "run", scene, "--events", str(log), "--no-hud-timing",
                        "--no-video", "--quiet", "--out", str(replay)],
                       capture_output=True, text=True)
    if not check(r.returncode == 0, "replay: exit %d: %s" % (r.returncode, r.stderr)):
        return
    for frame, png in sorted(shown.items()):
        written = replay / ("frame_%05d.png" % frame)
        check(written.is_file() and written.read_bytes() == png,
              "frame %d: the server's last picture equals the replay's %s" % (frame, written.name))
    check(len(shown) >= 4, "pictures compared: %d" % len(shown))
    for dump in sorted(live.glob("pause_*")):
        check((replay / dump.name).read_bytes() == dump.read_bytes(),
              "dump %s equals the replay's" % dump.name)
    check(any(live.glob("pause_*.json")), "the dump wrote its files")


SHOWN = {}  # frame -> the last picture the server showed of it (fetched while paused)


def command(url, body, expect_frame=None):
    """Applies one command that must succeed; records the picture shown after it when paused."""
    status, answer = post(url, body)
    if not check(status == 200 and answer.get("ok"), "%s: %s %s" % (body, status, answer)):
        return None
    if expect_frame is not None:
        check(answer["frame"] == expect_frame,
              "%s: frame %s, expected %s" % (body, answer["frame"], expect_frame))
    state = server_state(url)
    if not state["session"]["playing"]:
        status, png, headers = get(url + "api/frame.png?version=%d" % state["session"]["version"])
        check(status == 200 and headers.get("Content-Type") == "image/png", "frame.png answered")
        check(int(headers["X-Cdlab-Frame"]) == state["frame"] == answer["frame"],
              "%s: picture, state and answer name one frame" % body)
        SHOWN[state["frame"]] = png
    return state


def exercise(url, live, work):
    status, page, headers = get(url)
    check(status == 200 and b"serve-data" in page, "the page is served")
    check(b"<script src" not in page and b"<link" not in page, "the page needs no other file")

    state = server_state(url)
    check(state["frame"] == 0 and not state["session"]["playing"], "starts paused at frame 0")
    names = [b["name"] for b in state["bodies"]]

    # A watcher long-polling for newer pictures while commands come.
    seen = []

    def watch():
        version = state["session"]["version"]
        deadline = time.time() + 6
        while time.time() < deadline:
            s = json.loads(get(url + "api/state.json?after=%d" % version)[1])
            if s["session"]["version"] > version:
                seen.append(s["session"]["version"])
                version = s["session"]["version"]

    watcher = threading.Thread(target=watch)
    watcher.start()

    s = command(url, {"step": 3}, 3)
    s = command(url, {"show": ["obb"]}, 3)
    check(s and "obb" in s["session"]["layers"], "show obb: the state lists the layer")
    s = command(url, {"broadphase": "hgrid"}, 3)
    check(s and s["broadphase"] == "hgrid" and s["session"]["broadphase"] == "hgrid",
          "broadphase hgrid: the state says so")
    s = command(url, {"select": names[1]}, 3)
    check(s and s["session"]["selected"] == names[1], "select: the state names the body")
    check(s and names[1] in s["session"]["hud"], "select: the HUD names the body")
    command(url, {"camera": {"orbit": [30, 10], "zoom": 1.3}}, 3)
    command(url, {"step": 5}, 8)
    command(url, {"step": -2}, 6)
    status, answer = post(url, {"play": True})
    check(status == 200 and answer["ok"], "play")
    time.sleep(0.6)
    s = command(url, {"pause": True})
    played_to = s["frame"] if s else 0
    check(played_to > 6, "playing moved on: paused at frame %d" % played_to)
    # Played through frames 6.. again: their last pictures are the ones shown while playing.
    for frame in range(6, played_to):
        SHOWN.pop(frame, None)
    command(url, {"show": ["labels", "contacts"], "hide": ["obb"]}, played_to)
    command(url, {"dump": True}, played_to)
    command(url, "seek: {frame: 2}\n".encode(), 2)
    command(url, {"speed": 0.5, "camera": {"reset": True}}, 2)

    watcher.join()
    check(len(seen) >= 5, "the watcher saw the pictures change: %d versions" % len(seen))

    # Refused, changing nothing: the state after them is the state before.
    before = get(url + "api/state.json")[1]
    bad = [
        (b"{not json", 400, "command"),
        ({"jump": 1}, 400, "unknown key 'jump'"),
        ({"step": -5}, 400, "leaves the run's frames"),
        ({"select": "no such body"}, 400, "no body is named 'no such body'"),
        ({"broadphase": "fastest"}, 400, "unknown broad phase 'fastest'"),
        ({"show": ["sphere"], "hide": ["sphere"]}, 400, "both shown and hidden"),
        ({"wait": 2}, 400, "unknown key 'wait'"),
        (b"x" * (70 * 1024), 413, "larger than 64 KiB"),
    ]
    for body, code, words in bad:
        status, answer = post(url, body)
        check(status == code and not answer["ok"] and words in answer["error"],
              "bad command %r: %s %s" % (str(body)[:60], status, answer))
    for path, code, words in [("api/frame.png?after=x", 400, "'after'"),
                              ("api/timeline.json?from=-1", 400, "'from'"),
                              ("api/nothing", 404, "no such page"),
                              ("../../etc/passwd", 404, "")]:
        status, body, _ = get(url + path)
        check(status in (code, 400) and words in json.loads(body or b'{"error": ""}')["error"],
              "GET %s: %s %s" % (path, status, body[:120]))
    check(get(url + "api/state.json")[1] == before, "refused requests changed nothing")

    # A client that hangs up mid-request costs nothing.
    host, port = url.split("//")[1].rstrip("/").split(":")
    for partial in (b"POST /api/command HTTP/1.1\r\nContent-Length: 100\r\n\r\n{\"st",
                    b"GET /api/frame.png?after=999999 HTTP/1.1\r\n"):
        with socket.create_connection((host, int(port)), timeout=5) as sock:
            sock.sendall(partial)
    command(url, {"step": 1}, 3)
    command(url, {"step": 4, "show": ["aabb", "sphere"]}, 7)
    command(url, {"select": "none", "hide": ["hud"]}, 7)

    rows = json.loads(get(url + "api/timeline.json")[1])
    check(len(rows) == played_to + 1 and rows[-1]["frame"] == played_to,
          "the timeline has a row per frame reached: %d rows" % len(rows))


if __name__ == "__main__":
    main()
    sys.exit(report())
