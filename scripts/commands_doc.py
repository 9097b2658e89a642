#!/usr/bin/env python3
"""Writes docs/commands.md from `blurcue --help` and every `blurcue COMMAND [SUBCOMMAND] --help`.

The options are documented once, in the commands' own --help; this page is that text gathered in one place. The
test `docs_commands_current` runs this script with --check and fails when the page is stale.

usage: commands_doc.py BLURCUE --out docs/commands.md     # write the page
       commands_doc.py BLURCUE --check docs/commands.md   # exit 1 naming the first difference when it is stale
"""
import argparse
import difflib
import os
import re
import subprocess
import sys

HEADER = """# Commands

Every `blurcue` command with its options, as `blurcue COMMAND --help` prints them (this page is generated from that
text by `scripts/commands_doc.py`; do not edit it by hand: after changing a command's options run
`python3 scripts/commands_doc.py build/src/cli/blurcue --out docs/commands.md`, and the test
`docs_commands_current` fails until you do).

Errors, exit codes and how typed values are read: [running a study](running.md#errors-exit-codes-and-typed-values).
"""


def help_text(blurcue, words):
    # A fixed environment, so the page does not depend on who generates it (a data folder or Python set by hand).
    env = {"PATH": "/usr/bin:/bin", "LANG": "C.UTF-8", "COLUMNS": "120"}
    out = subprocess.run([blurcue, *words, "--help"], capture_output=True, text=True, env=env, timeout=60)
    if out.returncode != 0:
        sys.exit(f"commands_doc: `blurcue {' '.join(words)} --help` exited {out.returncode}: {out.stderr.strip()}")
    # The usage line names the binary by the path it was run from; the page names it blurcue.
    text = out.stdout.replace(blurcue, "blurcue")
    return text.rstrip() + "\n"


def subcommands(text):
    """The names CLI11 lists under its SUBCOMMANDS heading (any case), in the order it lists them."""
    names, inside = [], False
    for line in text.splitlines():
        if re.match(r"^subcommands:\s*$", line, re.IGNORECASE):
            inside = True
            continue
        if inside:
            m = re.match(r"^  (\S+)", line)
            if m:
                names.append(m.group(1))
            elif line.strip() and not line.startswith("   "):
                inside = False
    return names


def page(blurcue):
    top = help_text(blurcue, [])
    sections, index = [], []

    def walk(words):
        text = help_text(blurcue, words)
        title = "blurcue " + " ".join(words)
        anchor = re.sub(r"[^a-z0-9 -]", "", title.lower()).replace(" ", "-")
        index.append(f"- [`{title}`](#{anchor})")
        sections.append(f"## {title}\n\n```text\n{text}```\n")
        for sub in subcommands(text):
            walk(words + [sub])

    for command in subcommands(top):
        walk([command])
    return (HEADER + "\n" + "\n".join(index) + "\n\n## blurcue\n\n```text\n" + top + "```\n\n" +
            "\n".join(sections))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("blurcue")
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument("--out")
    group.add_argument("--check")
    args = parser.parse_args()
    blurcue = os.path.abspath(args.blurcue)
    text = page(blurcue)
    if args.out:
        with open(args.out + ".tmp", "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(args.out + ".tmp", args.out)
        print(f"commands_doc: wrote {args.out}")
        return
    with open(args.check, encoding="utf-8") as f:
        current = f.read()
    if current == text:
        print(f"ok: {args.check} is what `blurcue COMMAND --help` prints")
        return
    diff = list(difflib.unified_diff(current.splitlines(), text.splitlines(), args.check, "--help", lineterm="", n=1))
    print(f"FAIL: {args.check} is stale: run python3 scripts/commands_doc.py build/src/cli/blurcue "
          f"--out {args.check}\n" + "\n".join(diff[:40]))
    sys.exit(1)


if __name__ == "__main__":
    main()
