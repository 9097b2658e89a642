#!/usr/bin/env python3
"""The documentation as a reader meets it: the README is a short page (under 2,500 words) that names no path outside
the repository, and every relative link of README.md, docs/*.md and the protocol and analysis references (pages, images,
#anchors) leads somewhere.

usage: docs_check.py [REPO]      (default: the repository this file is in)
"""
import glob
import os
import re
import sys
import unittest

REPO = os.path.abspath(sys.argv.pop(1) if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
README = os.path.join(REPO, "README.md")
MAX_WORDS = 2500
# Pages other tasks add: the README links them before they exist.
LATER_PAGES = {"docs/track.md", "docs/blur-kernels.md"}


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def pages():
    refs = [os.path.join(REPO, p) for p in ("protocols/README.md", "analysis/README.md")]
    return [README] + sorted(glob.glob(os.path.join(REPO, "docs", "*.md"))) + [p for p in refs if os.path.exists(p)]


def without_code(text):
    """The text with fenced code blocks and inline code removed: a link inside code is an example, not a link."""
    text = re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)
    return re.sub(r"`[^`\n]*`", "", text)


def links(text):
    """Every markdown link and image target: [text](target) and ![alt](target), without a "title"."""
    pattern = r"!?\[[^\]]*\]\(([^)\s]+(?:\s+\"[^\"]*\")?)\)"
    return [m.group(1).split()[0] for m in re.finditer(pattern, without_code(text))]


def slug(heading):
    """GitHub's anchor for a heading: lower case, punctuation but - and _ dropped, spaces as -."""
    text = re.sub(r"`", "", heading.strip().lower())
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path):
    text = re.sub(r"^```.*?^```", "", read(path), flags=re.S | re.M)
    return {slug(m.group(1)) for m in re.finditer(r"^#{1,6}\s+(.*)$", text, flags=re.M)}


class ReadmeIsShort(unittest.TestCase):
    def test_readme_is_under_2500_words(self):
        words = len(read(README).split())
        self.assertLess(words, MAX_WORDS, f"README.md has {words} words; move detail to a page under docs/")


class NoPathOutsideTheRepository(unittest.TestCase):
    def test_readme_names_no_path_outside_the_repository(self):
        text = read(README)
        for pattern, what in [(r"\.\./", "a path above the repository (../)"), (r"/work/", "/work/"),
                              (r"\bshared/", "shared/"), (r"seed/thesis", "seed/thesis"), (r"/home/", "/home/")]:
            found = re.search(r"^.*" + pattern + r".*$", text, flags=re.M)
            self.assertIsNone(found, f"README.md names {what}: {found.group(0).strip() if found else ''}")

    def test_no_page_links_outside_the_repository(self):
        for page in pages():
            for target in links(read(page)):
                if re.match(r"^[a-z]+:", target) or target.startswith("#"):
                    continue
                resolved = os.path.normpath(os.path.join(os.path.dirname(page), target.split("#")[0]))
                self.assertTrue(resolved == REPO or resolved.startswith(REPO + os.sep),
                                f"{os.path.relpath(page, REPO)}: the link {target} leaves the repository")


class EveryRelativeLinkResolves(unittest.TestCase):
    def test_every_relative_link_and_anchor_resolves(self):
        problems = []
        for page in pages():
            for target in links(read(page)):
                if re.match(r"^[a-z]+:", target):  # http:, https:, mailto:
                    continue
                file_part, _, anchor = target.partition("#")
                path = os.path.normpath(os.path.join(os.path.dirname(page), file_part)) if file_part else page
                rel = os.path.relpath(path, REPO)
                if not os.path.exists(path):
                    if rel not in LATER_PAGES:
                        problems.append(f"{os.path.relpath(page, REPO)}: {target}: no such file")
                    continue
                if anchor and path.endswith(".md") and anchor not in anchors(path):
                    problems.append(f"{os.path.relpath(page, REPO)}: {target}: no heading #{anchor} in {rel}")
        self.assertEqual(problems, [])

    def test_the_link_check_finds_a_broken_link_and_anchor(self):
        # The checker itself, on a hand-made case: one good link, one missing file, one missing anchor.
        text = "[a](docs/running.md) [b](docs/nowhere.md) [c](docs/running.md#no-such-heading) `[d](x.md)`"
        self.assertEqual(links(text), ["docs/running.md", "docs/nowhere.md", "docs/running.md#no-such-heading"])
        self.assertEqual(slug("Errors, exit codes and typed values"), "errors-exit-codes-and-typed-values")
        self.assertEqual(slug("Planning a study (`blurcue plan`)"), "planning-a-study-blurcue-plan")


if __name__ == "__main__":
    unittest.main(verbosity=2)
