#!/usr/bin/env python3
"""Lines per file in */node/ and the longest functions there (brace-matched bodies of function
definitions), for issue 13's limits (node files ~300 lines, functions ~60 lines).

usage: cmake/node_sizes.py [ROOT] [N] [--no-tests]   N longest functions (default 10); --no-tests
leaves out *_test.cc files. A heuristic (no C++ parser): signatures ending in '{' on one line."""
import glob, re, sys
args = [a for a in sys.argv[1:] if a != '--no-tests']
no_tests = '--no-tests' in sys.argv
root = args[0] if args else '.'
files = sorted(f for f in glob.glob(root + '/*/node/*')
               if f.endswith(('.cc', '.h')) and not (no_tests and f.endswith('_test.cc')))
print('lines  file')
for f in files:
    n = sum(1 for _ in open(f))
    print(f'{n:5d}  {f[len(root)+1:]}')
# Functions: a line ending in '{' whose text looks like a signature (has '(' and ')' before the
# brace, not a control statement or lambda-only line), body to its matching brace.
ctrl = re.compile(r'^\s*(if|for|while|switch|else|do|try|catch|namespace|struct|class|enum|union)\b')
funcs = []
for f in files:
    lines = open(f).read().split('\n')
    i = 0
    while i < len(lines):
        line = lines[i]
        s = line.strip()
        # signature may span lines: gather back to a line at the same indentation start
        if s.endswith('{') and ')' in s and not ctrl.match(line) and not s.startswith(('[', '}', '//')) \
           and '=' not in s.split('(')[0] and not re.search(r'\]\s*\(.*\)\s*(->.*)?\{$', s) \
           and not s.startswith(('return', ':', ',')):
            depth = 0; j = i
            while j < len(lines):
                depth += lines[j].count('{') - lines[j].count('}')
                if depth <= 0 and j > i: break
                if depth <= 0 and j == i and lines[j].count('{') == lines[j].count('}'): break
                j += 1
            name = s.split('(')[0].split()[-1] if s.split('(')[0].split() else s
            funcs.append((j - i + 1, f[len(root)+1:], i + 1, name))
        i += 1
funcs.sort(reverse=True)
print('\nlongest functions (lines incl. signature and closing brace):')
for n, f, l, name in funcs[:int(args[1]) if len(args) > 1 else 10]:
    print(f'{n:4d}  {f}:{l}  {name}')
