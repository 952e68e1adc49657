"""callback_receiver.py PORTFILE LOGFILE — an HTTP server on 127.0.0.1 that
records every POST as one JSON line {"path", "body"} in LOGFILE and answers
204; a path ending in /flaky is answered 500 the first time, one ending in
/stall not before 30 s (a receiver that hangs: the daemon's client gives up
after 10 s).  Each request has its own thread.  Writes its port to PORTFILE
once listening (test_serve_callbacks.sh)."""
import http.server
import json
import sys
import time

port_file, log_file = sys.argv[1], sys.argv[2]
seen = set()


class Receiver(http.server.BaseHTTPRequestHandler):
    def do_POST(self):
        n = int(self.headers.get("Content-Length", 0))
        body = self.rfile.read(min(n, 1 << 22)).decode("utf-8", "replace")
        with open(log_file, "a") as f:
            f.write(json.dumps({"path": self.path, "body": body}) + "\n")
        first = self.path not in seen
        seen.add(self.path)
        if self.path.endswith("/stall"):
            time.sleep(30)
        self.send_response(500 if self.path.endswith("/flaky") and first else 204)
        self.end_headers()

    def log_message(self, *args):
        pass


server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Receiver)
server.daemon_threads = True
with open(port_file + ".tmp", "w") as f:
    f.write(str(server.server_port))
import os  # noqa: E402  (the rename makes the port file appear whole)

os.rename(port_file + ".tmp", port_file)
server.serve_forever()
