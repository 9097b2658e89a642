"""Opens the report's pages in headless Chromium as a reader would and checks every image loaded, every link points at
a file that exists, and the page logged nothing to the console (no script errors, no failed loads it reports).

usage: browser_check.py REPORT_DIR PAGE [PAGE ...]
Exit 0 with "ok: ..." or 1 with "FAIL: ..." - also where chromium is not installed (scripts/setup.sh --tests installs
it): a check that could not run never passes.
"""
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import urllib.parse

# A page of ours that loads the report page in a frame (same file:// origin with --allow-file-access-from-files),
# waits for it, and writes what it found into its own DOM, which --dump-dom prints.
CHECKER = """<!DOCTYPE html><html><body><iframe id="page" src="%s" style="width:1300px;height:900px"></iframe>
<pre id="result">pending</pre><script>
document.getElementById("page").addEventListener("load", function () {
  var doc = this.contentDocument, out = {images: 0, broken: [], links: [], title: doc.title,
                                        sections: doc.querySelectorAll("h2").length};
  for (var img of doc.images) { out.images++; if (!img.complete || img.naturalWidth === 0) out.broken.push(img.getAttribute("src")); }
  for (var a of doc.querySelectorAll("a[href]")) out.links.push(a.getAttribute("href"));
  document.getElementById("result").textContent = JSON.stringify(out);
});
</script></body></html>"""


def check(report_dir, page):
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        print("FAIL: chromium is not installed (Debian package chromium; scripts/setup.sh --tests installs it)")
        sys.exit(1)
    checker = os.path.join(report_dir, ".browser-check.html")
    with open(checker, "w", encoding="utf-8") as f:
        f.write(CHECKER % urllib.parse.quote(page))
    profile = tempfile.mkdtemp(prefix="blurcue-chromium-")
    try:
        proc = subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu", "--enable-logging=stderr",
                               "--v=0", f"--user-data-dir={profile}", "--allow-file-access-from-files",
                               "--virtual-time-budget=10000", "--dump-dom", "file://" + os.path.abspath(checker)],
                              capture_output=True, text=True, timeout=120)
    finally:
        os.remove(checker)
        shutil.rmtree(profile, True)
    match = re.search(r'<pre id="result">(.*?)</pre>', proc.stdout, re.S)
    if not match or match.group(1) == "pending":
        print(f"FAIL: {page}: chromium did not load the page (exit {proc.returncode})")
        sys.exit(1)
    found = json.loads(match.group(1).replace("&quot;", '"').replace("&amp;", "&").replace("&lt;", "<")
                       .replace("&gt;", ">"))
    console = [line for line in proc.stderr.splitlines() if ":CONSOLE" in line]
    problems = []
    if found["broken"]:
        problems.append(f"{len(found['broken'])} images did not load: {', '.join(found['broken'][:5])}")
    missing = [h for h in found["links"] if not h.startswith("#") and not h.startswith("http")
               and not os.path.isfile(os.path.join(report_dir, urllib.parse.unquote(h)))]
    if missing:
        problems.append(f"links to missing files: {', '.join(missing[:5])}")
    if console:
        problems.append(f"console messages: {console[:3]}")
    if problems:
        print(f"FAIL: {page}: " + "; ".join(problems))
        sys.exit(1)
    return f"{page}: {found['images']} images loaded, {len(found['links'])} links, {found['sections']} sections"


if __name__ == "__main__":
    results = [check(sys.argv[1], page) for page in sys.argv[2:]]
    print("ok: " + "; ".join(results))
