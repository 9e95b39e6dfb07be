#!/usr/bin/python3
"""The per-line MISRA C 2012 deviations: lists every inline cppcheck
suppression of a MISRA rule in src/, include/, hal/ and boards/ as the
table between the markers of docs/static-analysis.md.

    misra_deviations.py --check   fail if the table is not the tree's
                                  (tests/quality/static.sh runs it)
    misra_deviations.py --write   rewrite the table

A deviation is a comment on the line before the code (or at the end of a
line that starts with `}`):

    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */

with after the `;` the classes (D1 ...) whose justification the document
gives; a comment without a known class is an error."""
import collections
import os
import re
import subprocess
import sys

DOC = 'docs/static-analysis.md'
BEGIN = '<!-- misra-deviations: begin (tests/quality/misra_deviations.py --write) -->'
END = '<!-- misra-deviations: end -->'
CLASSES = ('D1', 'D2', 'D3', 'D4', 'D5', 'F')
SUPPRESS = re.compile(r'/\* cppcheck-suppress (\[[^]]*\]|\S+) ; ([^*]*) \*/')
FUNC = re.compile(r'^[A-Za-z_][A-Za-z0-9_ ]*[ *]([a-z_][a-z0-9_]*)\(')


def deviations():
    files = subprocess.check_output(['git', 'ls-files', 'src', 'include', 'hal', 'boards'],
                                    text=True).split()
    rows, errors, counts = [], [], collections.Counter()
    for path in sorted(f for f in files if f.endswith(('.c', '.h'))):
        with open(path, encoding='utf-8') as f:
            lines = f.read().split('\n')
        func = ''
        for i, line in enumerate(lines):
            m = FUNC.match(line)
            if m and not line.rstrip().endswith(';'):
                func = m.group(1)
            elif line.startswith('}'):
                func = ''
            s = SUPPRESS.search(line)
            if not s or 'misra-c2012-' not in s.group(1):
                continue
            rules = [r.replace('misra-c2012-', '') for r in s.group(1).strip('[]').split(', ')]
            classes = [t.split()[0] for t in s.group(2).split(', ') if t.strip()]
            if line.strip().startswith('/*'):
                where, code = i + 2, lines[i + 1].strip()
            else:
                where, code = i + 1, line[:s.start()].strip()
            if not classes or any(c not in CLASSES for c in classes):
                errors.append('%s:%d: deviation without a class (%s)' % (path, i + 1, '/'.join(CLASSES)))
            if len(code) > 60:
                code = code[:57] + '...'
            counts.update('rule ' + r for r in rules)
            counts.update('class ' + c for c in classes)
            rows.append('| `%s:%d` | %s | %s | %s | `%s` |' % (
                path, where, func or '(file scope)', ', '.join(rules), ', '.join(classes),
                code.replace('|', '\\|')))
    return rows, errors, counts


def main():
    os.chdir(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))
    mode = sys.argv[1] if len(sys.argv) > 1 else '--check'
    rows, errors, counts = deviations()
    tally = ', '.join('%s: %d' % kv for kv in sorted(counts.items()))
    table = '\n'.join(['| where | function | rules | class | code |', '|---|---|---|---|---|'] + rows)
    with open(DOC, encoding='utf-8') as f:
        doc = f.read()
    if BEGIN not in doc or END not in doc:
        errors.append('%s: no deviation table markers' % DOC)
    for e in errors:
        print('misra_deviations: ' + e)
    if errors:
        return 1
    head, rest = doc.split(BEGIN, 1)
    tail = rest.split(END, 1)[1]
    new = head + BEGIN + '\n' + table + '\n' + END + tail
    if mode == '--write':
        with open(DOC, 'w', encoding='utf-8') as f:
            f.write(new)
        print('misra_deviations: %d per-line deviations written to %s (%s)' % (len(rows), DOC, tally))
        return 0
    if new != doc:
        print('misra_deviations: the table in %s is not the tree\'s %d per-line deviations '
              '(tests/quality/misra_deviations.py --write)' % (DOC, len(rows)))
        return 1
    print('misra_deviations: %d per-line deviations, each listed in %s (%s)' % (len(rows), DOC, tally))
    return 0


if __name__ == '__main__':
    sys.exit(main())
