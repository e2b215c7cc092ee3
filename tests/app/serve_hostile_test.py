#!/usr/bin/python3
"""`cdlab serve` while one client holds many connections open: 50 that send nothing and 20 that
trickle a header byte a second. Meanwhile a new client must get /api/state.json within 1 s and a
watcher that follows the session as the page does (long-poll state.json, then that version's PNG,
over one kept-alive connection) must keep receiving frames; and the server must close every one
of the 70 by its 5 s request deadline (within 6.5 s of its opening), trickling or not. Then a
command still applies and SIGTERM stops the server with the session log on disk.

A server with a thread per connection fails it: its threads held by the first connections, the
new client waits until they go, and trickled headers restart its timeout with every byte.

    serve_hostile_test.py CDLAB SOURCE_DIR WORK_DIR

Exit 0 when every check holds; 1 with the failed checks listed otherwise.
"""
import http.client
import json
import select
import socket
import sys
import threading
import time
import urllib.request

from page_test_tools import Server, arguments, check, post, report

IDLE, TRICKLING = 50, 20
DEADLINE_S = 6.5       # the server's 5 s request deadline, and slack for a loaded machine
NEW_CLIENT_S = 1.0     # a new client's longest wait for state.json during the attack
WATCHER_GAP_S = 1.0    # the watcher's longest wait between two frames during the attack


def main():
    cdlab, source, work = arguments()
    scene = str(source / "scenes" / "coursework.yaml")
    log = work / "session.yaml"
    with Server([cdlab, "serve", scene, "--port", "0", "--out", str(work / "live"), "--session",
                 str(log)]) as server:
        url = server.url
        if url is None:
            return
        host, port = url.split("//")[1].rstrip("/").split(":")
        attack(url, host, int(port))
        out, err = server.stop()
        check("stopped; session log" in out and log.is_file(),
              "the stop is said and the log written: " + out)


def get_within(address, timeout):
    """GET with a timeout of its own: (status, body); raises OSError past it."""
    with urllib.request.urlopen(address, timeout=timeout) as r:
        return r.status, r.read()


class Watcher(threading.Thread):
    """Follows the session as the page does, over one kept-alive connection; keeps the time each
    new frame's PNG came in."""

    def __init__(self, host, port):
        super().__init__(daemon=True)
        self.connection = http.client.HTTPConnection(host, port, timeout=5)
        self.frames = []  # (time, version)
        self.errors = []
        self.stop = False

    def request(self, target):
        self.connection.request("GET", target)
        r = self.connection.getresponse()
        return r.status, r.read(), r.headers

    def run(self):
        version = 0
        while not self.stop:
            try:
                status, body, _ = self.request("/api/state.json?after=%d" % version)
                v = json.loads(body)["session"]["version"]
                if v == version:
                    continue
                status, png, headers = self.request("/api/frame.png?version=%d" % v)
                if status == 200 and png.startswith(b"\x89PNG"):
                    self.frames.append((time.monotonic(), v))
                version = v
            except (OSError, http.client.HTTPException, ValueError) as e:
                self.errors.append("%.2f s: %r" % (time.monotonic(), e))
                self.connection.close()
                time.sleep(0.1)


def attack(url, host, port):
    watcher = Watcher(host, port)
    watcher.start()
    time.sleep(1.0)
    check(len(watcher.frames) >= 5, "the watcher follows the session before the attack: %d frames"
          % len(watcher.frames))

    # The attack: 70 connections, opened at once; the trickling ones send a byte a second.
    start = time.monotonic()
    hostile = []  # [socket, opened at, trickles, closed at or None]
    for i in range(IDLE + TRICKLING):
        s = socket.create_connection((host, port), timeout=5)
        s.setblocking(False)
        hostile.append([s, time.monotonic(), i >= IDLE, None])
    trickle = b"GET /api/state.json HTTP/1.1\r\nHost: x\r\nX-Trickle: " + b"a" * 64

    def watch_closes():
        sent, next_byte = 0, time.monotonic()
        while time.monotonic() - start < 10 and any(h[3] is None for h in hostile):
            now = time.monotonic()
            if now >= next_byte:
                for h in hostile:
                    if h[2] and h[3] is None and sent < len(trickle):
                        try:
                            h[0].send(trickle[sent:sent + 1])
                        except BlockingIOError:
                            pass
                        except OSError:
                            h[3] = time.monotonic()
                sent, next_byte = sent + 1, next_byte + 1.0
            open_ones = [h for h in hostile if h[3] is None]
            readable, _, _ = select.select([h[0] for h in open_ones], [], [], 0.05)
            for h in open_ones:
                if h[0] in readable:
                    try:
                        if h[0].recv(4096) == b"":
                            h[3] = time.monotonic()
                    except BlockingIOError:
                        pass
                    except OSError:
                        h[3] = time.monotonic()

    closer = threading.Thread(target=watch_closes, daemon=True)
    closer.start()

    # New clients while every hostile connection is still open (the deadline is 5 s).
    for at in (1.0, 2.5, 4.0):
        time.sleep(max(0.0, start + at - time.monotonic()))
        t0 = time.monotonic()
        try:
            status, body = get_within(url + "api/state.json", NEW_CLIENT_S + 2)
            waited = time.monotonic() - t0
            print("new client %.1f s in: state.json in %.1f ms" % (at, 1e3 * waited))
            check(status == 200 and "session" in json.loads(body) and waited <= NEW_CLIENT_S,
                  "a new client %.1f s into the attack: state.json in %.3f s (at most %.1f s)"
                  % (at, waited, NEW_CLIENT_S))
        except OSError as e:
            check(False, "a new client %.1f s into the attack: no state.json within %.1f s: %r"
                  % (at, NEW_CLIENT_S + 2, e))

    closer.join(timeout=12)
    for kind, trickles in (("sending nothing", False), ("trickling", True)):
        group = [h for h in hostile if h[2] == trickles]
        late = [h for h in group if h[3] is None or h[3] - h[1] > DEADLINE_S]
        lived = sorted(round(h[3] - h[1], 2) for h in group if h[3] is not None)
        if lived:
            print("%s: %d of %d closed by the server, after %.2f..%.2f s"
                  % (kind, len(lived), len(group), lived[0], lived[-1]))
        check(not late, "%d connections %s: %d not closed by the server within %.1f s (closed "
              "after %s s)" % (len(group), kind, len(late), DEADLINE_S, lived))

    # The watcher's frames during the attack's first 5 s, while every hostile one was open.
    watcher.stop = True
    watcher.join(timeout=10)
    during = [t for t, _ in watcher.frames if start <= t <= start + 5.0]
    times = [start] + during + [start + 5.0]
    gap = max(b - a for a, b in zip(times, times[1:]))
    print("watcher: %d frames in the attack's first 5 s, longest wait %.0f ms"
          % (len(during), 1e3 * gap))
    check(len(during) >= 10 and gap <= WATCHER_GAP_S,
          "the watcher kept receiving frames during the attack: %d in 5 s, longest wait %.3f s "
          "(errors: %s)" % (len(during), gap, watcher.errors[:3]))
    for h in hostile:
        h[0].close()

    status, answer = post(url, {"show": ["obb"]})
    check(status == 200 and answer.get("ok"), "a command after the attack: %s %s"
          % (status, answer))


if __name__ == "__main__":
    main()
    sys.exit(report())
