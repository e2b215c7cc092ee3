#!/usr/bin/python3
"""How fast `cdlab serve` is as a user sees it (a bench, never run as a timed test):

  - frames per second reaching a client that follows the session as the page does (long-poll
    state.json, then fetch that version's PNG), while playing;
  - command -> changed frame: from sending a command (show/hide a layer, alternately) to having
    the PNG of the picture it changed, while paused and while playing; median and p95.

    serve_bench.py CDLAB SCENE [--seconds S] [--commands N] [--keep-alive] [--set KEY=VALUE ...]

Prints one line per figure; the scene's own size and frame rate apply unless --set changes them.
Each request opens a connection of its own unless --keep-alive sends them all over one kept-alive
connection, as a browser does.
"""
import argparse
import http.client
import json
import signal
import statistics
import subprocess
import threading
import time
import urllib.parse
import urllib.request

# The one connection every request goes over with --keep-alive; None: a connection per request.
kept_alive = None


def kept_alive_request(method, address, body=None):
    parts = urllib.parse.urlsplit(address)
    target = parts.path + ("?" + parts.query if parts.query else "")
    kept_alive.request(method, target, body=body)
    r = kept_alive.getresponse()
    return r.read(), r.headers


def get(address):
    if kept_alive:
        return kept_alive_request("GET", address)
    with urllib.request.urlopen(address, timeout=30) as r:
        return r.read(), r.headers


def post(url, body):
    if kept_alive:
        return json.loads(kept_alive_request("POST", url + "api/command",
                                             json.dumps(body).encode())[0])
    request = urllib.request.Request(url + "api/command", data=json.dumps(body).encode(),
                                     method="POST")
    with urllib.request.urlopen(request, timeout=30) as r:
        return json.loads(r.read())


def follow(url, seconds):
    """Frames a page-like client receives per second while the session plays."""
    version, received, start = 0, 0, time.time()
    while time.time() - start < seconds:
        state = json.loads(get(url + "api/state.json?after=%d" % version)[0])
        v = state["session"]["version"]
        if v != version:
            get(url + "api/frame.png?version=%d" % v)
            version = v
            received += 1
    return received / (time.time() - start)


def latencies(url, n):
    """Milliseconds from a command sent to the PNG of the picture it changed in hand."""
    out = []
    for i in range(n):
        t0 = time.perf_counter()
        post(url, {"show": ["obb"]} if i % 2 == 0 else {"hide": ["obb"]})
        get(url + "api/frame.png")
        out.append(1e3 * (time.perf_counter() - t0))
    return out


def p95(values):
    return sorted(values)[max(0, int(round(0.95 * len(values))) - 1)]


def main():
    global kept_alive
    parser = argparse.ArgumentParser()
    parser.add_argument("cdlab")
    parser.add_argument("scene")
    parser.add_argument("--seconds", type=float, default=5)
    parser.add_argument("--commands", type=int, default=60)
    parser.add_argument("--keep-alive", action="store_true")
    parser.add_argument("--set", action="append", default=[])
    args = parser.parse_args()
    command = [args.cdlab, "serve", args.scene, "--port", "0", "--paused", "--out",
               "/tmp/cdlab_serve_bench"]
    for kv in args.set:
        command += ["--set", kv]
    server = subprocess.Popen(command, stdout=subprocess.PIPE, text=True)
    try:
        url = server.stdout.readline().split()[2]
        if args.keep_alive:
            parts = urllib.parse.urlsplit(url)
            kept_alive = http.client.HTTPConnection(parts.hostname, parts.port, timeout=30)
        paused = latencies(url, args.commands)
        post(url, {"play": True})
        fps = follow(url, args.seconds)
        playing = latencies(url, args.commands)
        state = json.loads(get(url + "api/state.json")[0])
        print("scene %s: %d bodies" % (args.scene, len(state["bodies"])))
        print("frames reaching a client while playing: %.1f per second" % fps)
        for name, values in (("paused", paused), ("playing", playing)):
            print("command -> changed frame (%s, %d commands): median %.1f ms, p95 %.1f ms"
                  % (name, len(values), statistics.median(values), p95(values)))
    finally:
        server.send_signal(signal.SIGTERM)
        server.wait(timeout=30)


if __name__ == "__main__":
    main()
