#!/usr/bin/env python3
# scripts/function_lengths.py — functions longer than a limit (default 80
# lines) in C++ files, for the developers' guide rule "no function longer
# than ~80 lines in src/render or src/cli without a stated reason": a
# function passes when the comment above it says "longer than 80" (its
# reason). A brace scan, not a parser: a '{' opens a function body when the
# text before it (since the last ';', '{' or '}', template heads removed)
# has a ')' and is not a namespace/class/struct/enum header; lambdas and
# inner blocks count with the function they are in.
#
#   scripts/function_lengths.py [--limit N] FILE...     exit 1 when one is found
#   e.g. scripts/function_lengths.py src/render/*.{h,cpp} src/cli/*.{h,cpp}
import re
import sys


def strip(src):
    src = re.sub(r'/\*.*?\*/', lambda m: '\n' * m.group(0).count('\n'), src, flags=re.S)
    src = re.sub(r'//[^\n]*', '', src)
    src = re.sub(r'"(\\.|[^"\\\n])*"', '""', src)
    return re.sub(r"'(\\.|[^'\\\n])'", "''", src)


def long_functions(path, limit):
    raw = open(path).read().split('\n')
    stack, head, line = [], '', 1
    for ch in strip(open(path).read()):
        if ch == '\n':
            line += 1
        if ch == '{':
            h = re.sub(r'template\s*<[^{}]*?>', ' ', ' '.join(head.split()))
            if any(k == 'fn' for k, _, _ in stack):
                kind = 'block'
            elif re.search(r'\b(namespace|struct|class|enum|union)\b', h.split('(')[0]):
                kind = 'scope'
            elif ')' in h:
                kind = 'fn'
            else:
                kind = 'scope'
            stack.append((kind, line, h))
            head = ''
        elif ch == '}':
            if stack:
                kind, start, h = stack.pop()
                if kind == 'fn' and line - start + 1 > limit:
                    above = ' '.join(raw[max(0, start - 25):start]).lower()
                    if 'longer than 80' not in above:
                        yield start, line - start + 1, h
            head = ''
        elif ch == ';':
            head = ''
        else:
            head += ch


def main(argv):
    limit = 80
    if len(argv) > 1 and argv[0] == '--limit':
        limit, argv = int(argv[1]), argv[2:]
    found = 0
    for path in argv:
        for start, n, h in long_functions(path, limit):
            print(f'{path}:{start}: {n} lines, no reason stated: {h[-90:]}')
            found += 1
    return 1 if found else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
