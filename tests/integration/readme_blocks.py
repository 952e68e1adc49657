#!/usr/bin/env python3
"""readme_blocks.py README WORKDIR PORT — run README.md's shell blocks in order
in WORKDIR against a daemon on 127.0.0.1:PORT; one PASS/FAIL line per block.

Which blocks run (the marker is an HTML comment, the last non-blank line
before the fence: <!-- readme-test: WORDS -->):
  ```sh       every line is a command (a trailing \\ continues it); each must
              exit 0.  Marker "skip (why)": not run.  A command that starts
              with `make` is never run: such a block must be marked skip.
  ```console  a transcript: "$ " lines are commands (exit 0 each), the lines
              under one are its output.  Marker "real": that output is
              compared; "tty": the commands run on a pseudo-terminal
              (script(1)), as a user at a terminal sees them.
  other languages (json, text ...) are not run.

Comparing: a line "…" alone stands for any number of lines, a line ending in
"…" for any line starting with what precedes it.  Both sides are normalised:
trailing blanks and blank lines at the end dropped, on a terminal what a
carriage return redrew and the escape sequences taken out, and
  ISO 8601 times       2026-11-22T03:38:53.125Z   -> <TIME>
  SHA-256 (hex)        64 hexadecimal digits      -> <SHA256>
  SHA-256 (base64)     sha-256=:…=:               -> sha-256=:<SHA256>:
  durations            "1.3 s"                    -> "<SECONDS> s"
Job ids are bound, not normalised: the README's n-th id in an output is the
id the daemon gave at that place, and later commands and outputs use it (its
first 8 digits too).  localhost:8080 and 127.0.0.1:8080 are the test
daemon's port.  File sizes and every other figure are compared as they are.
"""
import os
import re
import subprocess
import sys

UUID = re.compile(r"[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}")
NORMAL = [
    (re.compile(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(\.\d+)?Z"), "<TIME>"),
    (re.compile(r"sha-256=:[A-Za-z0-9+/]+=*:"), "sha-256=:<SHA256>:"),
    (re.compile(r"\b[0-9a-f]{64}\b"), "<SHA256>"),
    (re.compile(r"\b\d+(\.\d+)? s\b"), "<SECONDS> s"),
]
ESCAPE = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")
TIMEOUT = 120 * int(os.environ.get("READMETEST_SLOW", "1"))


def blocks(text):
    """(line number, language, marker words, body lines) of each fenced block."""
    lines = text.split("\n")
    i, marker = 0, ""
    while i < len(lines):
        line = lines[i]
        m = re.match(r"<!--\s*readme-test:\s*(.*?)\s*-->\s*$", line)
        if m:
            marker = m.group(1)
        elif line.startswith("```"):
            lang, start, body = line[3:].strip(), i + 1, []
            i += 1
            while i < len(lines) and not lines[i].startswith("```"):
                body.append(lines[i])
                i += 1
            yield start, lang, marker.split("(")[0].split(), body
            marker = ""
        elif line.strip():
            marker = ""
        i += 1


def commands(body, console):
    """[(command, expected output lines)] of a block."""
    out, cur = [], None
    it = iter(body)
    for line in it:
        if console and not line.startswith("$ "):
            if cur is not None:
                cur[1].append(line)
            continue
        cmd = line[2:] if console else line
        while cmd.endswith("\\"):  # the shell joins the lines
            cmd += "\n" + next(it, "")
        if not cmd.strip() or cmd.lstrip().startswith("#"):
            continue
        cur = (cmd, [])
        out.append(cur)
    return out


def normal(lines, tty=False):
    res = []
    for line in lines:
        if tty:
            line = ESCAPE.sub("", line.split("\r")[-1])
        for rx, rep in NORMAL:
            line = rx.sub(rep, line)
        res.append(line.rstrip())
    while res and not res[-1]:
        res.pop()
    return res


def matches(exp, got):
    """exp (with … wildcards) against got, both normalised."""
    memo = {}

    def m(i, j):
        if (i, j) in memo:
            return memo[i, j]
        if i == len(exp):
            r = j == len(got)
        elif exp[i] == "…":
            r = any(m(i + 1, k) for k in range(j, len(got) + 1))
        elif j == len(got):
            r = False
        elif exp[i].endswith("…"):
            r = got[j].startswith(exp[i][:-1]) and m(i + 1, j + 1)
        else:
            r = exp[i] == got[j] and m(i + 1, j + 1)
        memo[i, j] = r
        return r

    return m(0, 0)


class Session:
    def __init__(self, workdir, port):
        self.workdir, self.port, self.ids = workdir, port, {}

    def bind(self, text):
        for old, new in self.ids.items():
            text = text.replace(old, new).replace(old[:8], new[:8])
        for host in ("localhost", "127.0.0.1"):
            text = text.replace(host + ":8080", "%s:%s" % (host, self.port))
        return text

    def learn(self, expected, got):
        ours = [u for u in dict.fromkeys(UUID.findall("\n".join(expected))) if u not in self.ids]
        theirs = [u for u in dict.fromkeys(UUID.findall(got)) if u not in self.ids.values()]
        for old, new in zip(ours, theirs):
            self.ids[old] = new

    def run(self, cmd, tty):
        argv = ["script", "-qec", cmd, "/dev/null"] if tty else ["sh", "-c", cmd]
        try:
            p = subprocess.run(argv, cwd=self.workdir, stdin=subprocess.DEVNULL,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            return 124, "(timed out after %d s)" % TIMEOUT
        text = p.stdout.decode("utf-8", "replace")
        return p.returncode, text.replace("\r\n", "\n")


def main():
    readme, workdir, port = sys.argv[1:4]
    s = Session(workdir, port)
    failed = 0
    for line, lang, marker, body in blocks(open(readme, encoding="utf-8").read()):
        if lang not in ("sh", "console"):
            continue
        name = "readme_block_line_%d" % line
        if "skip" in marker:
            print("SKIP %s: marked skip in the README" % name)
            continue
        why = None
        for cmd, expected in commands(body, lang == "console"):
            if re.match(r"\s*make\b", cmd):
                why = "`%s` is not run by the test: mark the block skip" % cmd
                break
            rc, got = s.run(s.bind(cmd), "tty" in marker)
            if "real" in marker:
                s.learn(expected, got)
            if rc != 0:
                why = "`%s` exited %d:\n%s" % (cmd, rc, got[-2000:])
                break
            if "real" in marker:
                exp = normal([s.bind(e) for e in expected])
                out = normal(got.split("\n"), "tty" in marker)
                if not matches(exp, out):
                    why = "`%s` printed\n%s\n--- the README shows\n%s" % (
                        cmd, "\n".join(out[:60]), "\n".join(exp))
                    break
        if why:
            failed += 1
            print("FAIL %s: %s" % (name, why))
        else:
            print("PASS %s" % name)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
