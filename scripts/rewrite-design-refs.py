#!/usr/bin/env python3
"""Rewrites references to the former docs/design.md into references to the pages it was split
into, using docs-mapping.tsv (old section -> new file, new section, new anchor).

    scripts/rewrite-design-refs.py [--dry-run] [--bare] [--tsv docs-mapping.tsv] [path ...]

Paths default to every file git tracks except docs/ and README.md, which were rewritten when
the page was split (run it once per file: a second pass would read the new numbers as old
ones); docs/benchmarks/ is always left alone: it quotes the old page verbatim. Rewritten:
  * prefixed references: `docs/design.md §3.5.1`, `design §5.3`, `design.md 8.3`,
    `(design §4.2)`, chains such as `design.md §5.13 - §5.16` or `design §5.17, §7.8`, also
    when a comment wraps between `design.md` and the section; a bare `docs/design.md` or
    `design.md#anchor` link;
  * bare references (`§4.5`, meaning design.md's section) in Markdown files under docs/ (the
    split pages were written against design.md's numbering) and, with --bare, everywhere.
    A bare § that names another document's section (`paper §4.2`, `§5.2 of the standard`,
    `(§3.1 there)`, `appendix A of [1]`, the references list of method.md) is left alone.
Code and other non-Markdown files get `docs/<page>.md §N`; Markdown files get a link to the
page (relative to the file) when the section is on another page, and a plain `§N` when it is on
the same page. Prints what it rewrote (or would) and every reference it could not resolve.
"""
import argparse
import os
import re
import subprocess
import sys

NUM = r'\d+(?:\.\d+)*'
SEP = r'\s*(?:,|–|—|-|\band\b|\bto\b|;)\s*'
# A comment may wrap between "design.md" and "§N".
WRAP = r'(?:\s*\n\s*(?://+|#+|\*|--)?)?\s*'
CHAIN_SEP = r'\s*(?:,|–|—|-|\band\b|\bto\b|;)' + WRAP
PREFIXED = re.compile(
    r'(?P<prefix>(?:docs/)?\bdesign(?:\.md)?)(?P<gap>,?' + WRAP + r')'
    r'(?P<chain>§\s?' + NUM + r'(?:' + CHAIN_SEP + r'§\s?' + NUM + r')*|' + NUM + r'(?![\d.]*\d))')
BARE = re.compile(r'§\s?(?P<n>' + NUM + r')(?P<rest>(?:' + CHAIN_SEP + r'§\s?' + NUM + r')*)')
LINK = re.compile(r'(?P<path>(?:\.\./|docs/)*design\.md)(?:#(?P<anchor>[\w-]+))?')
NOT_OURS_BEFORE = re.compile(r'(paper|LM-63|TM-25|standard|thesis|eq\.|\[\d\])\W*$', re.I)
NOT_OURS_AFTER = re.compile(r'^[^§\n]{0,6}(of \[\d\]|of the standard|there\b|appendix)')


def load_tsv(path):
    table = {}
    with open(path, encoding='utf-8') as f:
        for line in f:
            if line.startswith('#') or not line.strip():
                continue
            old, page, new, anchor, title = line.rstrip('\n').split('\t')
            table[old] = (page, new, anchor)
    return table


def old_anchors(table):
    # design.md's own anchors (README and docs linked to them): "6-architecture" etc.
    import unicodedata
    out = {}
    with open(os.path.join(os.path.dirname(TSV_PATH), 'docs-mapping.tsv'), encoding='utf-8') as f:
        for line in f:
            if line.startswith('#'):
                continue
            old, page, new, anchor, title = line.rstrip('\n').split('\t')
            h = (old.replace('.', '') + ' ' + title).lower()
            a = ''.join('-' if c == ' ' else c for c in h
                        if c in ' -_' or unicodedata.category(c)[0] in 'LN')
            out[a] = old
    return out


class Rewriter:
    def __init__(self, table, anchors, path, markdown, bare):
        self.table, self.anchors, self.path = table, anchors, path
        self.markdown, self.bare = markdown, bare
        self.here = os.path.normpath(path)
        self.resolved, self.unresolved, self.bare = [], [], []

    def target(self, page):
        if not self.markdown:
            return page
        return os.path.relpath(page, os.path.dirname(self.here) or '.')

    def same_page(self, page):
        return os.path.normpath(page) == self.here

    def render(self, nums, original, seps):
        """nums: old section numbers of one chain; seps: the separators between them."""
        locs = []
        for n in nums:
            if n not in self.table:
                self.unresolved.append((original, 'no section ' + n + ' in the mapping'))
                return None
            locs.append(self.table[n])
        out = ''
        prev_page = None
        for k, (page, new, anchor) in enumerate(locs):
            if k:
                out += seps[k - 1]
            sect = ('§' + new) if new else ''
            if self.markdown and self.same_page(page):
                piece = sect or 'this page'
            elif self.markdown:
                text = (os.path.basename(page) + (' ' + sect if sect else ''))
                if page == prev_page and sect:
                    text = sect
                link = self.target(page) + ('#' + anchor if anchor else '')
                piece = '[%s](%s)' % (text, link)
            else:
                piece = sect if (page == prev_page and sect) else (page + (' ' + sect if sect else ''))
            out += piece
            prev_page = page
        self.resolved.append((original, out))
        return out

    def split_chain(self, chain):
        nums = re.findall(NUM, chain)
        seps = re.findall(r'(' + CHAIN_SEP + r')§', chain)
        return nums, seps

    def prefixed(self, m):
        nums, seps = self.split_chain(m.group('chain'))
        r = self.render(nums, m.group(0), seps)
        if r is None:
            return m.group(0)
        gap = m.group('gap')
        # Keep a wrapped comment's line break: put it before the rewritten reference.
        lead = gap[:gap.rfind('\n')] if '\n' in gap else ''
        lead = ' ' if lead else ''
        return lead.rstrip() + r if not lead else r

    def link(self, m):
        anchor = m.group('anchor')
        if anchor is None:
            # A link to the whole page goes to the index; a mention in prose is left for a person.
            if self.markdown and m.string[max(0, m.start() - 2):m.start()] == '](':
                self.resolved.append((m.group(0), self.target('docs/README.md')))
                return self.target('docs/README.md')
            self.unresolved.append((m.group(0), 'the page named without a section'))
            return m.group(0)
        old = self.anchors.get(anchor)
        if old is None:
            self.unresolved.append((m.group(0), 'unknown anchor'))
            return m.group(0)
        page, new, new_anchor = self.table[old]
        out = self.target(page) + ('#' + new_anchor if new_anchor else '')
        if self.markdown and self.same_page(page):
            out = '#' + new_anchor
        self.resolved.append((m.group(0), out))
        return out

    def bare_ref(self, text, m):
        before = text[max(0, m.start() - 20):m.start()]
        after = text[m.end():m.end() + 40]
        if NOT_OURS_BEFORE.search(before) or NOT_OURS_AFTER.search(after):
            return m.group(0)
        # Link text of an in-page contents line: "[§1 Physical setup](#1-...)".
        if before.endswith('[') and re.match(r'^[^\]\n]*\]\(', after):
            return m.group(0)
        nums, seps = self.split_chain(m.group(0))
        r = self.render(nums, m.group(0), seps)
        return m.group(0) if r is None else r


def protect_references(text):
    # method.md's references list quotes the paper's own sections.
    i = text.find('\n## 5. References')
    return (text, '') if i < 0 else (text[:i], text[i:])


def process(path, table, anchors, args):
    markdown = path.endswith('.md')
    try:
        text = open(path, encoding='utf-8').read()
    except (UnicodeDecodeError, IsADirectoryError, FileNotFoundError):
        return None
    if '§' not in text and 'design' not in text:
        return None
    rw = Rewriter(table, anchors, path, markdown, args.bare)
    head, tail = protect_references(text) if path.endswith('docs/method.md') else (text, '')
    new = PREFIXED.sub(rw.prefixed, head)
    new = LINK.sub(rw.link, new)
    in_docs = markdown and os.path.normpath(path).startswith('docs' + os.sep)
    # Skip what the first pass produced (links and "docs/x.md §N" chains).
    pieces = re.split(r'(\[[^\]]*\]\([^)]*\)|docs/[a-z]+\.md §[\d.]+'
                      r'(?:(?:\s*(?:,|–|-|and|to)' + WRAP + r')(?:docs/[a-z]+\.md )?§[\d.]+)*)', new)
    if args.bare or in_docs:
        for k in range(0, len(pieces), 2):
            pieces[k] = BARE.sub(lambda m, s=pieces[k]: rw.bare_ref(s, m), pieces[k])
        new = ''.join(pieces)
    elif not markdown:
        offset = 0
        for k, piece in enumerate(pieces):
            if k % 2 == 0:
                for m in BARE.finditer(piece):
                    before = piece[max(0, m.start() - 20):m.start()]
                    after = piece[m.end():m.end() + 40]
                    if NOT_OURS_BEFORE.search(before) or NOT_OURS_AFTER.search(after):
                        continue
                    line = new.count('\n', 0, offset + m.start()) + 1
                    rw.bare.append('%s:%d: %s' % (path, line, m.group(0)))
            offset += len(piece)
    new += tail
    if new != text and not args.dry_run:
        with open(path, 'w', encoding='utf-8') as f:
            f.write(new)
    return rw


def main():
    global TSV_PATH
    p = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    p.add_argument('paths', nargs='*')
    p.add_argument('--tsv', default='docs-mapping.tsv')
    p.add_argument('--dry-run', action='store_true')
    p.add_argument('--bare', action='store_true')
    p.add_argument('--quiet', action='store_true')
    p.add_argument('--list-bare', action='store_true')
    args = p.parse_args()
    TSV_PATH = os.path.abspath(args.tsv)
    table = load_tsv(args.tsv)
    anchors = old_anchors(table)
    if args.paths:
        files = []
        for a in args.paths:
            if os.path.isdir(a):
                for d, _, fs in os.walk(a):
                    files += [os.path.join(d, f) for f in fs]
            else:
                files.append(a)
    else:
        files = subprocess.run(['git', 'ls-files'], capture_output=True, text=True,
                               check=True).stdout.split('\n')
    files = sorted(os.path.normpath(f) for f in files if f)
    if not args.paths:
        # docs/ and README.md were rewritten when the page was split: their bare § already
        # use the new numbering, so a second pass would misread them.
        files = [f for f in files if not f.startswith('docs' + os.sep) and f != 'README.md']
    files = [f for f in files if not f.startswith(os.path.join('docs', 'benchmarks'))
             and f != os.path.normpath(args.tsv) and not f.endswith('rewrite-design-refs.py')]
    n_ok = n_bad = n_bare = 0
    for f in files:
        rw = process(f, table, anchors, args)
        if rw is None:
            continue
        for old, new in rw.resolved:
            n_ok += 1
            if not args.quiet:
                print('%s: %r -> %r' % (f, old, new))
        for old, why in rw.unresolved:
            n_bad += 1
            print('%s: UNRESOLVED %r: %s' % (f, old, why))
        for b in rw.bare:
            n_bare += 1
            if args.list_bare:
                print('BARE ' + b)
    print('%d reference(s) %s, %d not resolved, %d bare § left in code (--bare rewrites them, '
          '--list-bare lists them)' %
          (n_ok, 'resolvable' if args.dry_run else 'rewritten', n_bad, n_bare), file=sys.stderr)


if __name__ == '__main__':
    main()
