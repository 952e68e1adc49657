"""ogc_conformance.py BASE_URL PACKD TMPDIR EXAMPLE_BODY — OGC API – Processes
Part 1 as third-party clients see packd: OWSLib (Debian python3-owslib) for
discovery, plain urllib for execute -> poll -> results, the job-list
parameters, Prefer: respond-sync and response raw, and the result digest.
Prints PASS/FAIL lines (tests/run.sh adds them up)."""
import hashlib
import json
import subprocess
import sys
import time
import urllib.error
import urllib.parse
import urllib.request

from owslib.ogcapi.processes import Processes

B, PACKD, T, BODY = sys.argv[1:5]
body = json.load(open(BODY))
failed = 0


def check(name, cond, detail=""):
    global failed
    if cond:
        print("PASS", name)
    else:
        failed += 1
        print("FAIL", name + (": " + str(detail)[:400] if detail else ""))


def http(method, url, data=None, headers=None):
    """(status, headers, body bytes); no exception on 4xx/5xx."""
    if not url.startswith("http"):
        url = B + url
    req = urllib.request.Request(url, data=data, method=method, headers=headers or {})
    try:
        with urllib.request.urlopen(req, timeout=60) as r:
            return r.status, r.headers, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.headers, e.read()


def get_json(url):
    s, h, b = http("GET", url)
    return s, json.loads(b) if b else None


def execute(doc, prefer=None):
    h = {"Content-Type": "application/json"}
    if prefer:
        h["Prefer"] = prefer
    return http("POST", "/processes/pack/execution", json.dumps(doc).encode(), h)


def wait_final(job_url, seconds=60):
    end = time.time() + seconds
    while time.time() < end:
        s, st = get_json(job_url)
        if st and st.get("status") in ("successful", "failed", "dismissed"):
            return st
        time.sleep(0.2)
    return None


def jobs(query):
    return get_json("/jobs?" + query)


# --- discovery with OWSLib ------------------------------------------------
p = Processes(B)
check("owslib_landing_links_absolute", p.links and all(l["href"].startswith("http") for l in p.links), p.links)
api = p.api()
check("owslib_api", api.get("openapi", "").startswith("3.0"), list(api)[:5])
conf = p.conformance().get("conformsTo", [])
check("owslib_conformance_job_list",
      "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/job-list" in conf, conf)
ids = [q["id"] for q in p.processes().get("processes", [])]
check("owslib_process_list", "pack" in ids and "homogenize" in ids, ids)
desc = p.process("pack")
declared = set(desc.get("outputs", {}))
check("owslib_process_description",
      desc.get("id") == "pack" and "domain" in desc.get("inputs", {}) and
      "sync-execute" in desc.get("jobControlOptions", []), desc.get("jobControlOptions"))
check("outputs_declared", {"summary", "result", "xdmf"} <= declared and
      all("contentMediaType" in o["schema"] for o in desc["outputs"].values()), declared)

# --- execute -> poll -> results (async) -------------------------------------
s, h, b = execute(body)
loc = h.get("Location", "")
check("execute_201_absolute_location", s == 201 and loc.startswith("http"), (s, loc))
st = wait_final(loc)
check("poll_successful", st and st["status"] == "successful", st)
s, res = get_json(loc + "/results")
check("results_document", s == 200 and set(res) <= declared and {"summary", "result", "xdmf"} <= set(res),
      (s, res and list(res)))
s, hh, h5 = http("GET", res["result"]["href"])
check("result_download_sha256", s == 200 and hashlib.sha256(h5).hexdigest() == res["result"]["sha256"])
digest = res["summary"]["value"].get("result_digest", "")
open(T + "/async.h5", "wb").write(h5)
ins = json.loads(subprocess.run([PACKD, "inspect", T + "/async.h5"], capture_output=True, text=True).stdout)
check("result_digest_in_summary_and_file",
      len(digest) == 64 and ins.get("result_digest") == digest and ins.get("result_digest_verified") is True,
      (digest, ins.get("result_digest")))
s, summ = get_json(loc + "/results/summary")
check("summary_output", s == 200 and summ.get("result_digest") == digest)
first_job = st

# --- Prefer: respond-sync --------------------------------------------------
s, h, b = execute(body, "respond-sync")
check("sync_200_results_document",
      s == 200 and h.get("Preference-Applied") == "respond-sync" and 'rel="monitor"' in h.get("Link", "") and
      "result" in json.loads(b), (s, dict(h)))
sync_doc = json.loads(b) if s == 200 else {}
check("sync_same_result_digest", sync_doc.get("summary", {}).get("value", {}).get("result_digest") == digest)
raw = dict(body, response="raw")
s, h, b = execute(raw, "respond-sync")
check("sync_raw_hdf5_bytes", s == 200 and h.get("Content-Type") == "application/x-hdf5" and b[:4] == b"\x89HDF",
      (s, h.get("Content-Type")))
s, h, b = execute(body, "respond-sync, wait=0")
check("sync_wait_over_201", s == 201 and "Preference-Applied" not in h, s)
s, h, b = execute(raw)
st = wait_final(h.get("Location", B + "/jobs/none"))
s2, h2, b2 = http("GET", h.get("Location", "") + "/results")
check("async_raw_results_hdf5", s == 201 and st and s2 == 200 and b2[:4] == b"\x89HDF", (s, s2))
s3, h3, b3 = http("GET", h.get("Location", "") + "/results", headers={"Accept": "application/json"})
check("async_raw_results_json_when_asked", s3 == 200 and "result" in json.loads(b3), s3)
one = dict(body, outputs={"summary": {"transmissionMode": "value"}})
s, h, b = execute(one, "respond-sync")
check("sync_one_output_by_value", s == 200 and json.loads(b).get("result_digest") == digest, s)
s, h, b = execute(dict(body, response="bytes"))
check("execute_bad_response_400", s == 400 and b"response" in b, s)

# --- the job list ----------------------------------------------------------
s, h, b = http("DELETE", "/jobs/" + first_job["jobID"])
s, all_ = jobs("limit=100")
n_all = all_["numberMatched"]
n_ok = jobs("status=successful")[1]["numberMatched"]
s, both = jobs("status=successful&status=dismissed&limit=100")
check("status_repeated", s == 200 and both["numberMatched"] == n_ok + 1 and
      {j["status"] for j in both["jobs"]} == {"successful", "dismissed"}, both.get("numberMatched"))
s, both2 = jobs("status=successful,dismissed&limit=100")
check("status_comma_separated", s == 200 and both2["numberMatched"] == both["numberMatched"])
s, pr = jobs("processID=pack,homogenize")
check("processID_array", s == 200 and pr["numberMatched"] == n_all, (pr.get("numberMatched"), n_all))
check("processID_unknown", jobs("processID=nothing")[1]["numberMatched"] == 0)
check("type_process", jobs("type=process")[1]["numberMatched"] == n_all)
s, e = jobs("type=batch")
check("type_other_400", s == 400 and "type" in e.get("detail", ""), e)
created = first_job["created"]
s, at = jobs("datetime=" + urllib.parse.quote(created))
check("datetime_instant", s == 200 and [j["jobID"] for j in at["jobs"]] == [first_job["jobID"]],
      (created, at.get("numberMatched")))
s, after = jobs("datetime=" + urllib.parse.quote(created) + "/..")
check("datetime_open_end", s == 200 and after["numberMatched"] == n_all, after.get("numberMatched"))
s, before = jobs("datetime=../2000-01-01T00:00:00Z")
check("datetime_open_start", s == 200 and before["numberMatched"] == 0)
s, iv = jobs("datetime=2000-01-01T00:00:00Z/2999-01-01T00:00:00%2B02:00")
check("datetime_closed_offset", s == 200 and iv["numberMatched"] == n_all)
s, e = jobs("datetime=2026-13-01T00:00:00Z")
check("datetime_bad_400", s == 400 and "datetime" in e.get("detail", ""), e)
s, e = jobs("datetime=2030-01-01T00:00:00Z/2020-01-01T00:00:00Z")
check("datetime_reversed_400", s == 400)
ran = jobs("status=successful,failed,running&limit=100")[1]["numberMatched"]
s, d0 = jobs("minDuration=0&limit=100")
check("minDuration_ran_jobs", s == 200 and d0["numberMatched"] >= ran and
      all(j.get("started") for j in d0["jobs"]), (d0.get("numberMatched"), ran))
check("maxDuration_bounds", jobs("minDuration=3600")[1]["numberMatched"] == 0 and
      jobs("maxDuration=3600&limit=100")[1]["numberMatched"] == d0["numberMatched"])
s, e = jobs("maxDuration=-1")
check("duration_bad_400", s == 400 and "maxDuration" in e.get("detail", ""), e)
s, big = jobs("limit=20000")
self_link = [l["href"] for l in big.get("links", []) if l["rel"] == "self"]
check("limit_clamped", s == 200 and self_link and "limit=10000" in self_link[0], self_link)
s, e = jobs("limit=0")
check("limit_bad_400", s == 400 and "limit" in e.get("detail", ""), e)
check("limit_default_10", len(jobs("")[1]["jobs"]) == min(10, n_all))
s, page1 = jobs("limit=1&status=successful,dismissed")
nxt = [l["href"] for l in page1["links"] if l["rel"] == "next"]
check("next_link_keeps_filters", nxt and nxt[0].startswith("http") and "status=successful,dismissed" in nxt[0], nxt)
s, page2 = get_json(nxt[0]) if nxt else (0, {})
prev = [l["href"] for l in page2.get("links", []) if l["rel"] == "prev"]
check("paging", s == 200 and page2["jobs"] and page2["jobs"][0]["jobID"] != page1["jobs"][0]["jobID"] and
      prev and get_json(prev[0])[1]["jobs"][0]["jobID"] == page1["jobs"][0]["jobID"])
check("numberReturned", page1.get("numberReturned") == 1)

# --- the command-line client checks the digest ------------------------------
job = dict(body, process="pack")
json.dump(job, open(T + "/job.json", "w"))
r = subprocess.run([PACKD, "submit", T + "/job.json", "--server", B, "--wait", "-o", T + "/cli.h5"],
                   capture_output=True, text=True, timeout=120)
out = json.loads(r.stdout) if r.returncode == 0 else {}
check("submit_wait_checks_result_digest", out.get("result_digest") == digest, (r.returncode, r.stderr[-300:]))
sys.exit(1 if failed else 0)
