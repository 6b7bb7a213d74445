#!/usr/bin/env python3
"""Checks the Markdown documents of the repository: every relative link resolves to a file or
folder of the repository, and no document points outside it (a path like ../shared/x does not
exist in a clone). Usage: check_links.py REPO_ROOT. Exit 1 with one line per problem."""
import os
import re
import sys

LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
UPWARD = re.compile(r"(?<![\w/.])((?:\.\./)+[\w.-][\w./-]*)")


def documents(root):
    for top in ("README.md", "BENCHMARKS.md", "RELIABILITY.md"):
        yield os.path.join(root, top)
    for folder in ("docs", os.path.join("bench", "notes")):
        for dirpath, _, files in os.walk(os.path.join(root, folder)):
            for f in sorted(files):
                if f.endswith(".md"):
                    yield os.path.join(dirpath, f)


def inside(root, path):
    return os.path.commonpath([root, os.path.realpath(path)]) == root


def main():
    root = os.path.realpath(sys.argv[1])
    problems = []
    for doc in documents(root):
        if not os.path.exists(doc):
            continue
        here = os.path.dirname(doc)
        rel = os.path.relpath(doc, root)
        text = open(doc, encoding="utf-8").read()
        for n, line in enumerate(text.splitlines(), 1):
            for target in LINK.findall(line):
                if re.match(r"^[a-z]+:", target) or target.startswith("#"):
                    continue
                path = os.path.join(here, target.split("#")[0])
                if not inside(root, path):
                    problems.append(f"{rel}:{n}: link '{target}' leaves the repository")
                elif not os.path.exists(path):
                    problems.append(f"{rel}:{n}: link '{target}' does not resolve")
            for target in UPWARD.findall(line):
                if not inside(root, os.path.join(here, target)):
                    problems.append(f"{rel}:{n}: path '{target}' points outside the repository")
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} problem(s): fix the links, or bring what they point to into the repository")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
