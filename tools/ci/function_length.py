"""Refuses functions longer than a limit (default 120 lines, from the line of the opening brace to
the closing one) in host/, kernels/, tests/ and tools/ C++ and OpenCL sources.

Braces are counted after comments, string and character literals and preprocessor lines are
blanked out. A '{' opens a function where the text since the previous ';', '{' or '}' ends with
')' (optionally const/override/noexcept/-> T) and does not start with a control keyword; lambdas
and local classes count in the function around them.

Run from the repository root: python3 tools/ci/function_length.py [LIMIT]
"""
import pathlib
import re
import sys

CONTROL = re.compile(
    r'^(if|for|while|switch|catch|else|do|return|namespace|class|struct|enum|union)\b')
GLOBS = ['host/**/*.cpp', 'host/**/*.h', 'kernels/**/*.cl', 'kernels/**/*.h', 'tests/**/*.cpp',
         'tools/**/*.cpp']


def blank(src):
    """The source with comments, literals and preprocessor lines replaced by spaces (newlines
    kept, so that line numbers hold)."""
    out, i, n = [], 0, len(src)

    def spaces(a, b):
        return ''.join(ch if ch == '\n' else ' ' for ch in src[a:b])

    while i < n:
        c = src[i]
        if src.startswith('//', i):
            j = src.find('\n', i)
            j = n if j < 0 else j
        elif src.startswith('/*', i):
            j = src.find('*/', i + 2)
            j = n if j < 0 else j + 2
        elif c in '"\'':
            raw = re.match(r'R"([^(]*)\(', src[i - 1:]) if c == '"' and i > 0 and src[i - 1] == 'R' else None
            end = src.find(')' + raw.group(1) + '"', i) if raw else -1
            if raw and end >= 0:
                j = end + len(raw.group(1)) + 2
            else:
                j = i + 1
                while j < n and src[j] != c:
                    j += 2 if src[j] == '\\' else 1
                j += 1
        elif c == '#' and src[:i].rsplit('\n', 1)[-1].strip() == '':
            j = i
            while True:
                k = src.find('\n', j)
                k = n if k < 0 else k
                if k < n and src[k - 1] == '\\':
                    j = k + 1
                    continue
                j = k
                break
        else:
            out.append(c)
            i += 1
            continue
        out.append(spaces(i, j))
        i = j
    return ''.join(out)


def function_name(head):
    """The name of the function whose signature is `head`, or None."""
    h = re.sub(r'\s*(const|override|final|noexcept|mutable)\s*$', '', head)
    h = re.sub(r'\s*->\s*[\w:<>,\s*&]+$', '', h)
    if ') :' in h or '):' in h:
        h = re.sub(r'\s*:\s*[\w:]+\s*\(.*\)\s*$', '', h)
    if not h.endswith(')'):
        return None
    words = h.split('(')[0].split()
    if not words or '=' in h.split('(')[0] or words[-1].endswith(']'):
        return None
    return None if CONTROL.match(words[-1]) else words[-1]


def functions(path):
    """(lines, name, first line) of each outermost function in the file."""
    s = blank(path.read_text(errors='replace'))
    found, stack, head_start = [], [], 0
    for i, c in enumerate(s):
        if c == ';':
            head_start = i + 1
        elif c == '{':
            name = None
            if not any(stack):
                name = function_name(' '.join(s[head_start:i].split()))
            stack.append((name, s.count('\n', 0, i) + 1) if name else None)
            head_start = i + 1
        elif c == '}':
            top = stack.pop() if stack else None
            if top:
                end = s.count('\n', 0, i) + 1
                found.append((end - top[1] + 1, top[0], top[1]))
            head_start = i + 1
    return found


def main():
    limit = int(sys.argv[1]) if len(sys.argv) > 1 else 120
    over = []
    for pattern in GLOBS:
        for path in sorted(pathlib.Path('.').glob(pattern)):
            over += [(n, f'{path}:{line} {name}') for n, name, line in functions(path) if n > limit]
    for n, where in sorted(over, reverse=True):
        print(f'function-length: {where} has {n} lines (limit {limit})')
    return 1 if over else 0


if __name__ == '__main__':
    sys.exit(main())
