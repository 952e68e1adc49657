#!/usr/bin/env python3
"""html_check.py FILE — a page runs no script of its own and styles nothing
inline: parsed as a browser would (html.parser), it has no <script> element
with a body, no event-handler attribute (on…), no style attribute or
element and no javascript: URL.  Exits 1 naming the first offence."""
import sys
from html.parser import HTMLParser


class Check(HTMLParser):
    def __init__(self):
        super().__init__()
        self.bad = []
        self.in_script = False

    def handle_starttag(self, tag, attrs):
        if tag == "style":
            self.bad.append("<style> element")
        self.in_script = tag == "script"
        for name, value in attrs:
            if name.startswith("on") or name == "style":
                self.bad.append(f"<{tag} {name}=…>")
            if name in ("href", "src", "action") and (value or "").strip().lower().startswith("javascript:"):
                self.bad.append(f"<{tag} {name}=javascript:…>")

    def handle_endtag(self, tag):
        self.in_script = False

    def handle_data(self, data):
        if self.in_script and data.strip():
            self.bad.append("inline script")


c = Check()
c.feed(open(sys.argv[1], encoding="utf-8").read())
if c.bad:
    print(sys.argv[1] + ": " + "; ".join(c.bad))
    sys.exit(1)
