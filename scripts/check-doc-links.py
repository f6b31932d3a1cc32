#!/usr/bin/env python3
"""Checks the relative links of the Markdown pages (README.md, docs/**, fuzz/README.md ...):
every `](file.md#anchor)` / `](#anchor)` / `](path)` must name an existing file and, for a
Markdown target, an existing heading (GitHub's anchors: lower case, spaces to '-', other
punctuation dropped).  scripts/check-doc-links.py [file.md ...]  (default: every tracked .md)
Exit 1 and one line per dangling link when any is broken."""
import os
import re
import subprocess
import sys
import unicodedata

LINK = re.compile(r'\]\(([^)\s]+)\)')
FENCE = re.compile(r'^\s*(```|~~~)')


def anchor(heading):
    out = ''
    for c in heading.strip().lower():
        if c == ' ':
            out += '-'
        elif c in '-_' or unicodedata.category(c)[0] in 'LN':
            out += c
    return out


def anchors(path, cache={}):
    if path not in cache:
        seen, result = {}, set()
        fenced = False
        for line in open(path, encoding='utf-8'):
            if FENCE.match(line):
                fenced = not fenced
            if fenced:
                continue
            m = re.match(r'^#{1,6} (.*)$', line.rstrip('\n'))
            if m:
                a = anchor(m.group(1))
                n = seen.get(a, 0)
                seen[a] = n + 1
                result.add(a if n == 0 else '%s-%d' % (a, n))
        cache[path] = result
    return cache[path]


def main():
    files = sys.argv[1:] or [f for f in subprocess.run(
        ['git', 'ls-files', '*.md'], capture_output=True, text=True, check=True).stdout.split()]
    bad = 0
    for f in files:
        fenced = False
        for n, line in enumerate(open(f, encoding='utf-8'), 1):
            if FENCE.match(line):
                fenced = not fenced
            if fenced:
                continue
            for target in LINK.findall(line):
                if re.match(r'^[a-z]+:', target):
                    continue  # http:, mailto:
                path, _, frag = target.partition('#')
                dest = os.path.normpath(os.path.join(os.path.dirname(f), path)) if path else f
                if not os.path.exists(dest):
                    print('%s:%d: %s: no such file' % (f, n, target))
                    bad += 1
                elif frag and dest.endswith('.md') and frag not in anchors(dest):
                    print('%s:%d: %s: no heading with that anchor in %s' % (f, n, target, dest))
                    bad += 1
    print('%d file(s) checked, %d dangling link(s)' % (len(files), bad), file=sys.stderr)
    sys.exit(1 if bad else 0)


if __name__ == '__main__':
    main()
