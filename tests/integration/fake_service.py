#!/usr/bin/env python3
"""fake_service.py PORTFILE LOGFILE — a stand-in packd service on 127.0.0.1
for the client's failure paths (test_client.sh): results whose bytes do not
match their SHA-256 or their stated result_digest, a download cut short, a failed job with a partial file,
a result link naming another host.
Writes its port to PORTFILE and each request's Authorization header to
LOGFILE."""
import hashlib
import http.server
import json
import sys

BODY = b"HDF5-like bytes of a result file\n" * 64
SHA = hashlib.sha256(BODY).hexdigest()


class Handler(http.server.BaseHTTPRequestHandler):
    def log_message(self, *args):
        pass

    def reply(self, code, body, ctype="application/json", headers=None, length=None):
        self.send_response(code)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(len(body) if length is None else length))
        for k, v in (headers or {}).items():
            self.send_header(k, v)
        self.end_headers()
        self.wfile.write(body)

    def do_GET(self):
        with open(sys.argv[2], "a") as f:
            f.write("%s %s\n" % (self.path, self.headers.get("Authorization", "-")))
        parts = self.path.strip("/").split("/")  # jobs ID results [result]
        job = parts[1] if len(parts) > 1 else ""
        if parts[-1] == "results" and job == "failed":
            doc = {"type": "urn:packd:problem:job-failed", "title": "Job failed", "status": 422,
                   "detail": "ran out of wall time", "jobID": job, "jobStatus": "failed",
                   "partial_result": {"href": "/jobs/failed/results/result", "sha256": SHA}}
            return self.reply(422, json.dumps(doc).encode(), "application/problem+json")
        if parts[-1] == "results" and job in ("good", "tampered", "short", "badheader", "abs", "digest"):
            # "abs": a public URL the client does not use (a proxy's name)
            base = "http://public.invalid:9" if job == "abs" else ""
            summary = {"fake": True}
            if job == "digest":  # states a content hash the bytes do not have
                summary["result_digest"] = "0" * 64
            doc = {"result": {"href": base + "/jobs/%s/results/result" % job, "sha256": SHA,
                              "size": len(BODY)}, "summary": {"value": summary}}
            return self.reply(200, json.dumps(doc).encode())
        if parts[-1] == "result":
            hdr = {"X-Content-SHA256": "0" * 64 if job == "badheader" else SHA}
            if job == "tampered":
                return self.reply(200, BODY.replace(b"HDF5", b"HDF6"), "application/x-hdf5", hdr)
            if job == "short":  # the connection closes before Content-Length bytes
                self.close_connection = True
                return self.reply(200, BODY[:100], "application/x-hdf5", hdr, length=len(BODY))
            return self.reply(200, BODY, "application/x-hdf5", hdr)
        self.reply(404, b'{"type":"urn:packd:problem:no-such-job","title":"No such job","status":404}',
                   "application/problem+json")


srv = http.server.HTTPServer(("127.0.0.1", 0), Handler)
with open(sys.argv[1] + ".tmp", "w") as f:
    f.write(str(srv.server_address[1]))
import os
os.rename(sys.argv[1] + ".tmp", sys.argv[1])
srv.serve_forever()
