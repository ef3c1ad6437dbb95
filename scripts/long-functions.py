#!/usr/bin/env python3
"""Lists functions in Rust sources longer than a limit (default 150 lines).

Usage: scripts/long-functions.py [LIMIT] [DIR...]   (default DIRs: src crates/*/src)

A function runs from its `fn` line to the line of the brace that closes its
body; braces inside strings, chars and comments are skipped. Exit 1 when any
function is over the limit.
"""
import glob
import os
import re
import sys

FN = re.compile(r'^\s*(pub(\([^)]*\))?\s+)?(const\s+)?(async\s+)?(unsafe\s+)?(extern\s+"[^"]*"\s+)?fn\s+(\w+)')


def strip(line, state):
    """The line with string, char and comment contents removed; state carries
    an open block comment or raw string across lines."""
    out, i, n = [], 0, len(line)
    while i < n:
        if state['block']:
            j = line.find('*/', i)
            if j < 0:
                return ''.join(out)
            state['block'] = False
            i = j + 2
            continue
        if state['raw'] is not None:
            j = line.find(state['raw'], i)
            if j < 0:
                return ''.join(out)
            i = j + len(state['raw'])
            state['raw'] = None
            continue
        if state['str']:
            if line[i] == '\\':
                i += 2
                continue
            if line[i] == '"':
                state['str'] = False
            i += 1
            continue
        c = line[i]
        if line.startswith('//', i):
            break
        if line.startswith('/*', i):
            state['block'] = True
            i += 2
            continue
        m = re.match(r'b?r(#*)"', line[i:])
        if m and (i == 0 or not (line[i - 1].isalnum() or line[i - 1] == '_')):
            state['raw'] = '"' + m.group(1)
            i += len(m.group(0))
            continue
        if c == '"':
            state['str'] = True
            i += 1
            continue
        if c == "'":
            m = re.match(r"'(\\.[^']*|[^\\'])'", line[i:])
            if m:
                i += len(m.group(0))
                continue
        out.append(c)
        i += 1
    return ''.join(out)


def functions(path):
    lines = open(path, encoding='utf-8').read().split('\n')
    state = {'block': False, 'raw': None, 'str': False}
    stack = []  # (name, start line, depth at which the body opened)
    depth = 0
    pending = None
    brackets = 0  # open ( and [ of a signature: a `;` inside is a type's, as in [T; N]
    for no, raw in enumerate(lines, 1):
        code = strip(raw, state)
        m = FN.match(code)
        if m:
            pending = (m.group(7), no)
            brackets = 0
        for ch in code:
            if ch in '([':
                brackets += 1
            elif ch in ')]':
                brackets -= 1
            if ch == '{':
                depth += 1
                if pending:
                    stack.append((pending[0], pending[1], depth))
                    pending = None
            elif ch == '}':
                if stack and stack[-1][2] == depth:
                    name, start, _ = stack.pop()
                    yield name, start, no - start + 1
                depth -= 1
            elif ch == ';' and pending and brackets <= 0:
                pending = None  # a declaration without a body
    return


def main():
    args = sys.argv[1:]
    limit = 150
    if args and args[0].isdigit():
        limit = int(args.pop(0))
    dirs = args or ['src'] + sorted(glob.glob('crates/*/src'))
    long = []
    for d in dirs:
        for root, _, files in os.walk(d):
            for f in files:
                if f.endswith('.rs'):
                    p = os.path.join(root, f)
                    long += [(n, p, s, name) for name, s, n in functions(p) if n > limit]
    for n, p, s, name in sorted(long, reverse=True):
        print(f'{n:5} {p}:{s} {name}')
    sys.exit(1 if long else 0)


if __name__ == '__main__':
    main()
