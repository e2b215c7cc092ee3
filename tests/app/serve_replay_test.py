#!/usr/bin/python3
"""`cdlab serve --replay` on a run's recording, over its HTTP API: the pictures it shows of
frames reached in any order (seek, step back) are the run's own PNGs byte for byte (HUD hidden:
a paused live HUD says PAUSED), nothing is simulated past the recording, and one pair's history
(GET /api/pair.json) is the frame ranges the run's --trace lists it in, over the whole recording;
then a live `cdlab serve` gives the same history for the frames it has reached. Bad pair
requests are refused with the name that is wrong.

    serve_replay_test.py CDLAB SOURCE_DIR WORK_DIR

Exit 0 when every check holds; 1 with the failed checks listed otherwise.
"""
import json
import subprocess
import sys
import urllib.parse

from page_test_tools import Server, arguments, check, failures, get, post, report, server_state

FRAMES = 90


def ranges(frames):
    out = []
    for f in frames:
        if out and out[-1][1] == f - 1:
            out[-1][1] = f
        else:
            out.append([f, f])
    return out


def history(url, a, b):
    query = urllib.parse.urlencode({"a": a, "b": b})
    status, body, _ = get(url + "api/pair.json?" + query)
    return status, json.loads(body)


def main():
    cdlab, source, work = arguments()
    scene = str(source / "scenes" / "coursework.yaml")
    run, rec, trace = work / "run", work / "c.rec", work / "trace.jsonl"
    r = subprocess.run([cdlab, "run", scene, "--frames", str(FRAMES), "--no-video", "--quiet",
                        "--no-hud-timing", "--set", "draw.hud=false", "--out", str(run),
                        "--record", str(rec), "--trace", str(trace)],
                       capture_output=True, text=True)
    if not check(r.returncode == 0, "run --record: %d %s" % (r.returncode, r.stderr)):
        return
    lines = [json.loads(line) for line in trace.read_text().splitlines()]
    check(len(lines) == FRAMES, "trace lines: %d" % len(lines))
    # A pair the run flags in some frames and not others, and one it never flags.
    counts = {}
    for t in lines:
        for a, b in t["flagged_names"]:
            counts[(a, b)] = counts.get((a, b), 0) + 1
    pairs = sorted(p for p, n in counts.items() if n < FRAMES)
    if not check(pairs, "the run flags some pair in some frames only"):
        return
    never = ("ball0", "ship23") if ("ball0", "ship23") not in counts else None

    def expected(pair, last):
        flagged = [t["frame"] for t in lines if t["frame"] <= last and list(pair) in t["flagged_names"]]
        colliding = [t["frame"] for t in lines
                     if t["frame"] <= last and list(pair) in t["colliding_names"]]
        return ranges(flagged), ranges(colliding)

    with Server([cdlab, "serve", "--replay", str(rec), "--port", "0", "--paused", "--out",
                 str(work / "live")]) as replay:
        url = replay.url
        if url is None:
            return
        status, page, _ = get(url)
        check(status == 200 and b"A replay of the recording c.rec" in page, "the page says replay")
        for frame in [37, 0, 89, 12, 13, 64]:
            status, answer = post(url, {"seek": {"frame": frame}})
            check(status == 200 and answer["frame"] == frame, "seek %d: %s" % (frame, answer))
            state = server_state(url)
            status, png, headers = get(url + "api/frame.png?version=%d" % state["session"]["version"])
            check(int(headers["X-Cdlab-Frame"]) == frame, "frame %d shown" % frame)
            check(png == (run / ("frame_%05d.png" % frame)).read_bytes(),
                  "frame %d: the replay's picture is the run's PNG" % frame)
        status, answer = post(url, {"step": -3})
        check(status == 200 and answer["frame"] == 61, "step back in a replay: %s" % answer)
        status, answer = post(url, {"seek": {"frame": FRAMES}})
        check(status == 400 and "0..%d" % (FRAMES - 1) in answer["error"],
              "nothing past the recording: %s" % answer)
        post(url, {"seek": {"frame": FRAMES - 1}})
        status, answer = post(url, {"step": 1})
        check(status == 400 and "leaves the run's frames 0..%d" % (FRAMES - 1) in answer["error"],
              "no step past the recording: %s" % answer)
        for pair in pairs[:6]:
            status, h = history(url, *pair)
            flagged, colliding = expected(pair, FRAMES - 1)
            check(status == 200 and h["frames"] == FRAMES and h["flagged"] == flagged and
                  h["colliding"] == colliding,
                  "history of %s in the replay: %s, the trace says %s %s" % (pair, h, flagged, colliding))
        # Either order of the names.
        status, h = history(url, pairs[0][1], pairs[0][0])
        check(status == 200 and h["flagged"] == expected(pairs[0], FRAMES - 1)[0], "b, a order")
        if never:
            status, h = history(url, *never)
            check(status == 200 and h["flagged"] == [] and h["colliding"] == [],
                  "a pair never flagged: %s" % h)
        for query, wrong in [({"a": "ball0"}, "?a=NAME&b=NAME"), ({"a": "ball0", "b": "nobody"},
                             "no body named 'nobody'"), ({"a": "ball0", "b": "ball0"}, "twice")]:
            status, body, _ = get(url + "api/pair.json?" + urllib.parse.urlencode(query))
            answer = json.loads(body)
            check(status == 400 and wrong in answer.get("error", ""),
                  "pair.json %s refused: %s %s" % (query, status, answer))

    # A live session: the history of the frames simulated so far.
    with Server([cdlab, "serve", scene, "--port", "0", "--paused", "--out",
                 str(work / "live2"), "--set", "draw.hud=false"]) as live:
        url = live.url
        if url is None:
            return
        status, answer = post(url, {"seek": {"frame": 50}})
        check(status == 200 and answer["frame"] == 50, "live seek: %s" % answer)
        post(url, {"step": -20})  # frames reached again change nothing
        for pair in pairs[:6]:
            status, h = history(url, *pair)
            flagged, colliding = expected(pair, 50)
            check(status == 200 and h["frames"] == 51 and h["flagged"] == flagged and
                  h["colliding"] == colliding,
                  "history of %s live: %s, the trace says %s %s" % (pair, h, flagged, colliding))


if __name__ == "__main__":
    try:
        main()
    except Exception as e:  # a crash of the test is a failure with its reason
        failures.append("the test stopped: %r" % e)
    sys.exit(report())
