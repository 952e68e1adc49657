#!/usr/bin/env python3
"""conn_client.py — loopback clients for test_serve_conn.sh and bench/service.sh.

  hold  PORT --slow N --idle M [--per-src K] [--src-from I] [--reconnect 1] --ready FILE --seconds S
        N slow-loris connections (a request whose header grows by one byte per
        second per connection, never finished) and M idle ones (connected, silent),
        spread over source addresses 127.0.0.I, 127.0.0.I+1, ... with K connections
        each.  Writes FILE (slow=, idle=, closed=, failed=) once all are open, keeps
        them S seconds (or until SIGTERM), prints the final counts.  --reconnect 1:
        a slow connection the server closes is opened again from its address at
        once (reopened= counts them), so the flood never lets up.
  sse   PORT PATH --n N [--per-src K] [--src-from I] --ready FILE --seconds S
        N Server-Sent Events listeners of PATH; FILE is written once every stream
        has sent its first line (or S seconds passed).  Then waits until every
        stream has ended (or S seconds): prints n=, started=, ended=,
        last_end_s= (after FILE was written), status_events=.
  probe PORT [--path P] [--n N] [--src A] [--interval I]
        N sequential GETs (--interval seconds apart), a new connection each: n=, fail=, p50_ms=, p99_ms=,
        max_ms= (a failure: no answer within 2 s or not a 200).
  burst PORT PATH BODYFILE --n N --conc C --out FILE
        N POSTs of BODYFILE (application/json), C at a time; the id of every
        201 is appended to FILE as it arrives.  n=, answered=, failed=.
  jobs  PORT IDFILE --timeout S
        Waits until every job in IDFILE is final: total=, successful=,
        failed=, dismissed=, missing=, pending=.
  open  PORT --n N --src A --wait W
        N connections from source A, then after W seconds: how many the server
        has closed: n=, closed= (per-IP limit, idle timeout).
Every answer is one line of key=value pairs.
"""
import math
import os
import resource
import selectors
import signal
import socket
import sys
import time


def raise_nofile():
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft < hard:
        resource.setrlimit(resource.RLIMIT_NOFILE, (hard, hard))


def opt(args, name, default):
    if name in args:
        i = args.index(name)
        v = args[i + 1]
        del args[i:i + 2]
        return type(default)(v)
    return default


def connect(port, src):
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    s.bind((src, 0))
    s.settimeout(5)
    s.connect(("127.0.0.1", port))
    s.setblocking(False)
    return s


def sources(first, per_src):
    i = first
    while True:
        for _ in range(per_src):
            yield "127.0.%d.%d" % (i // 250, 1 + i % 250)
        i += 1


def kv(doc):
    """One line of key=value pairs (what the shell scripts grep)."""
    return " ".join("%s=%s" % (k, v) for k, v in doc.items())


def write_ready(path, doc):
    with open(path + ".tmp", "w") as f:
        f.write(kv(doc) + "\n")
    os.rename(path + ".tmp", path)


def hold(args):
    port = int(args[0])
    nslow, nidle = opt(args, "--slow", 0), opt(args, "--idle", 0)
    per_src, first = opt(args, "--per-src", 50), opt(args, "--src-from", 2)
    ready, seconds = opt(args, "--ready", ""), opt(args, "--seconds", 30.0)
    reconnect = opt(args, "--reconnect", 0)
    src = sources(first, per_src)
    sel = selectors.DefaultSelector()
    slow, closed, failed, reopened = {}, 0, 0, 0  # slow: an ordered set
    origin = {}

    def open_slow(a):
        s = connect(port, a)
        s.send(b"GET /healthz HTTP/1.1\r\nHost: x\r\nX-Slow: ")
        slow[s] = None
        origin[s] = a
        sel.register(s, selectors.EVENT_READ)

    for k in range(nslow + nidle):
        try:
            if k < nslow:
                open_slow(next(src))
                continue
            s = connect(port, next(src))
        except OSError:
            failed += 1
            continue
        sel.register(s, selectors.EVENT_READ)
    stop = [False]
    signal.signal(signal.SIGTERM, lambda *a: stop.__setitem__(0, True))

    def pump(until):
        nonlocal closed, reopened
        while time.time() < until and not stop[0]:
            for key, _ in sel.select(timeout=0.05):
                try:
                    data = key.fileobj.recv(4096)
                except BlockingIOError:
                    continue
                except OSError:
                    data = b""
                if not data:
                    closed += 1
                    sel.unregister(key.fileobj)
                    key.fileobj.close()
                    if key.fileobj in slow:
                        del slow[key.fileobj]
                        a = origin.pop(key.fileobj)
                        if reconnect and ready_written[0]:
                            try:
                                open_slow(a)
                                reopened += 1
                            except OSError:
                                failed += 1

    ready_written = [False]
    pump(time.time() + 0.5)  # connections the server refuses are closed at once
    doc = {"slow": len(slow), "idle": len(sel.get_map()) - len(slow), "closed": closed, "failed": failed}
    if ready:
        write_ready(ready, doc)
    ready_written[0] = True
    end = time.time() + seconds
    # One header byte per connection per second, spread over the second.
    while time.time() < end and not stop[0]:
        t0 = time.time()
        for i, s in enumerate(list(slow)):
            try:
                s.send(b"a")
            except OSError:
                pass
            if i % 100 == 99:
                pump(min(t0 + 1.0 * (i + 1) / max(len(slow), 1), end))
        pump(min(t0 + 1.0, end))
    doc.update(closed=closed, reopened=reopened, failed=failed, open_slow=len(slow))
    print(kv(doc))


def sse(args):
    port, path = int(args[0]), args[1]
    n = opt(args, "--n", 10)
    per_src, first = opt(args, "--per-src", 50), opt(args, "--src-from", 2)
    ready, seconds = opt(args, "--ready", ""), opt(args, "--seconds", 30.0)
    src = sources(first, per_src)
    sel = selectors.DefaultSelector()
    state = {}
    for _ in range(n):
        try:
            s = connect(port, next(src))
        except OSError:
            continue
        s.send(("GET %s HTTP/1.1\r\nHost: x\r\nAccept: text/event-stream\r\n\r\n" % path).encode())
        state[s] = {"buf": b"", "started": False, "ended": None}
        sel.register(s, selectors.EVENT_READ)
    t_ready = None
    status_events = 0
    deadline = time.time() + seconds
    while time.time() < deadline:
        started = sum(1 for v in state.values() if v["started"])
        if t_ready is None and started == n:
            t_ready = time.time()
            if ready:
                write_ready(ready, {"started": started})
        if all(v["ended"] is not None for v in state.values()):
            break
        for key, _ in sel.select(timeout=0.05):
            s = key.fileobj
            v = state[s]
            try:
                data = s.recv(65536)
            except BlockingIOError:
                continue
            except OSError:
                data = b""
            if not data:
                v["ended"] = time.time()
                sel.unregister(s)
                s.close()
                continue
            if b"retry: 2000" in v["buf"] + data:
                v["started"] = True
            v["buf"] = (v["buf"] + data)[-256:]
            status_events += data.count(b"event: status")
            if v["buf"].endswith(b"\r\n0\r\n\r\n"):  # the last chunk: the stream is over
                v["ended"] = time.time()
                sel.unregister(s)
                s.close()
    if t_ready is None and ready:
        write_ready(ready, {"started": sum(1 for v in state.values() if v["started"])})
    ends = [v["ended"] for v in state.values() if v["ended"] is not None]
    print(kv({
        "n": n, "started": sum(1 for v in state.values() if v["started"]),
        "ended": len(ends),
        "last_end_s": round(max(ends) - t_ready, 3) if ends and t_ready else -1,
        "status_events": status_events}))


def probe(args):
    port = int(args[0])
    path, n, src = opt(args, "--path", "/healthz"), opt(args, "--n", 50), opt(args, "--src", "127.0.0.1")
    interval = opt(args, "--interval", 0.0)
    times, fail = [], 0
    req = ("GET %s HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n" % path).encode()
    for _ in range(n):
        t0 = time.perf_counter()
        try:
            s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            s.bind((src, 0))
            s.settimeout(2.0)
            s.connect(("127.0.0.1", port))
            s.sendall(req)
            data = b""
            while True:
                chunk = s.recv(65536)
                if not chunk:
                    break
                data += chunk
            s.close()
            ok = data.startswith(b"HTTP/1.1 200")
        except OSError:
            ok = False
        dt = (time.perf_counter() - t0) * 1000
        if interval > 0:
            time.sleep(interval)
        if ok:
            times.append(dt)
        else:
            fail += 1
            times.append(2000.0)
    times.sort()

    def pct(p):  # nearest rank
        return round(times[max(0, math.ceil(p * len(times)) - 1)], 2)

    print(kv({"n": n, "fail": fail, "p50_ms": pct(0.5), "p99_ms": pct(0.99),
                      "max_ms": round(times[-1], 2)}))


def http(port, method, path, body=None, timeout=10.0):
    """(status, body) of one request on a new connection; (0, b"") when it failed."""
    import http.client
    try:
        c = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
        headers = {"Content-Type": "application/json"} if body is not None else {}
        c.request(method, path, body=body, headers=headers)
        r = c.getresponse()
        data = r.read()
        c.close()
        return r.status, data
    except (OSError, http.client.HTTPException):
        return 0, b""


def burst(args):
    import threading
    port, path, bodyfile = int(args[0]), args[1], args[2]
    n, conc, out = opt(args, "--n", 200), opt(args, "--conc", 20), opt(args, "--out", "")
    body = open(bodyfile, "rb").read()
    lock = threading.Lock()
    counts = {"answered": 0, "failed": 0}
    todo = list(range(n))
    f = open(out, "a")

    def run():
        while True:
            with lock:
                if not todo:
                    return
                todo.pop()
            status, data = http(port, "POST", path, body)
            with lock:
                if status == 201:
                    counts["answered"] += 1
                    job = data.split(b'"jobID": "', 1)[1].split(b'"', 1)[0].decode()
                    f.write(job + "\n")
                    f.flush()
                else:
                    counts["failed"] += 1

    threads = [threading.Thread(target=run) for _ in range(conc)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    f.close()
    print(kv({"n": n, "answered": counts["answered"], "failed": counts["failed"]}))


def jobs(args):
    port, idfile = int(args[0]), args[1]
    timeout = opt(args, "--timeout", 120.0)
    ids = [l.strip() for l in open(idfile) if l.strip()]
    final = {}
    end = time.time() + timeout
    while time.time() < end and len(final) < len(ids):
        for i in ids:
            if i in final:
                continue
            status, data = http(port, "GET", "/jobs/" + i)
            if status == 404:
                final[i] = "missing"
            elif status == 200:
                st = data.split(b'"status": "', 1)[1].split(b'"', 1)[0].decode()
                if st in ("successful", "failed", "dismissed"):
                    final[i] = st
        time.sleep(0.5)
    vals = list(final.values())
    print(kv({"total": len(ids), "successful": vals.count("successful"), "failed": vals.count("failed"),
              "dismissed": vals.count("dismissed"), "missing": vals.count("missing"),
              "pending": len(ids) - len(final)}))


def open_conns(args):
    port = int(args[0])
    n, src, wait = opt(args, "--n", 10), opt(args, "--src", "127.0.0.1"), opt(args, "--wait", 1.0)
    socks = []
    for _ in range(n):
        try:
            socks.append(connect(port, src))
        except OSError:
            pass
    time.sleep(wait)
    closed = n - len(socks)
    for s in socks:
        try:
            if s.recv(1, socket.MSG_PEEK) == b"":
                closed += 1
        except BlockingIOError:
            pass
        except OSError:
            closed += 1
    print(kv({"n": n, "closed": closed}))


def main():
    raise_nofile()
    cmd, args = sys.argv[1], sys.argv[2:]
    {"hold": hold, "sse": sse, "probe": probe, "open": open_conns, "burst": burst, "jobs": jobs}[cmd](args)


if __name__ == "__main__":
    main()
