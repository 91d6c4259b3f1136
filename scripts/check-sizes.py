#!/usr/bin/env python3
"""Counts source files over 600 lines and functions over 80 lines (issue 25), and fails on any.

usage: check-sizes.py [--max-file-lines N] [--max-function-lines N] [--list] [--known FILE] [ROOT]

Looks at the C++ of src/, include/, apps/ and python/src/ under ROOT (default: this checkout) and
at the Python of python/gyrodrift/. A C++ function is a brace block opened at namespace or class
scope after a header with a parameter list (lambdas and local classes count towards the function
around them); its length runs from the first line of its header to its closing brace. Comments,
string and character literals are blanked first, so braces inside them do not count. Python
functions are measured with the ast module (first line of the def to its last line).
Prints the counts (and with --list every offender); exit code 1 when a count is not zero.
--known FILE (CTest passes scripts/size-known.txt) lists offenders not yet split, one a line,
"file PATH LINES" or "function PATH NAME LINES": each may stay until it is split but not grow, and
nothing new may join them, so the counts only go down; an entry no longer needed is reported (to
be removed from the list).
"""
import argparse
import ast
import os
import re
import sys

CXX_DIRS = ["src", "include", "apps", "python/src"]
PY_DIRS = ["python/gyrodrift"]
CXX_EXT = (".cc", ".h", ".inc", ".cpp", ".hpp")
NOT_FUNCTION = re.compile(r"^\s*(namespace\b|extern\s+\"C\"|struct\b|class\b|union\b|enum\b)")
CONTROL = re.compile(r"\b(if|for|while|switch|catch|do|else)\s*$")


def blank(text):
    """The text with comments and literals replaced by spaces (newlines kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = text.find(")" + m.group(1) + '"', i)
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # digit separator 1'000
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def cxx_functions(path):
    """(name, first line, length) of each function defined at namespace or class scope."""
    text = blank(open(path, encoding="utf-8", errors="replace").read())
    text = re.sub(r"^[ \t]*#.*$", lambda m: " " * len(m.group(0)), text, flags=re.M)  # directives
    functions, stack = [], []  # stack of (kind, start line, name)
    header_start = 0  # offset where the text before the next brace began
    line_of = lambda offset: text.count("\n", 0, offset) + 1
    for m in re.finditer(r"[{};]", text):
        c, pos = m.group(0), m.start()
        if c == ";":
            if not stack or stack[-1][0] in ("namespace", "class"):
                header_start = pos + 1
            continue
        if c == "{":
            header = text[header_start:pos]
            outer = all(k in ("namespace", "class") for k, _, _ in stack)
            kind = "block"
            if outer:
                h = " ".join(header.split())
                if NOT_FUNCTION.match(h) or not h:
                    kind = "namespace" if h.startswith(("namespace", "extern")) or not h else "class"
                    if re.match(r"^\s*(struct|class|union|enum)\b.*\)\s*$", h) and "=" not in h:
                        kind = "function"  # a function returning a struct type, rare
                elif "(" in h and ")" in h and not re.search(r"=\s*$|=\s*[^=(]*$", h.split("(")[0]) \
                        and not CONTROL.search(h.split("(")[0]):
                    kind = "function"
                elif re.search(r"\b(struct|class)\b", h) and "(" not in h:
                    kind = "class"
            start = text[header_start:pos]
            lead = len(start) - len(start.lstrip())
            name = " ".join(header.split("(")[0].split()[-1:]) if kind == "function" else ""
            stack.append((kind, line_of(header_start + lead), name))
            header_start = pos + 1
        else:  # "}"
            if not stack:
                continue
            kind, first, name = stack.pop()
            if kind == "function" and all(k in ("namespace", "class") for k, _, _ in stack):
                functions.append((name, first, line_of(pos) - first + 1))
            if not stack or stack[-1][0] in ("namespace", "class"):
                header_start = pos + 1
    return functions


def py_functions(path):
    tree = ast.parse(open(path, encoding="utf-8").read())
    return [(node.name, node.lineno, node.end_lineno - node.lineno + 1)
            for node in ast.walk(tree) if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("root", nargs="?", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    ap.add_argument("--max-file-lines", type=int, default=600)
    ap.add_argument("--max-function-lines", type=int, default=80)
    ap.add_argument("--list", action="store_true", help="print every offender")
    ap.add_argument("--known", help="offenders allowed until they are split (not to grow)")
    a = ap.parse_args()
    files, big_files, big_functions, names = 0, [], [], {}
    for dirs, ext, measure in ((CXX_DIRS, CXX_EXT, cxx_functions), (PY_DIRS, (".py", ".pyi"), py_functions)):
        for d in dirs:
            for folder, _, entries in os.walk(os.path.join(a.root, d)):
                for e in sorted(entries):
                    if not e.endswith(ext):
                        continue
                    path = os.path.join(folder, e)
                    rel = os.path.relpath(path, a.root)
                    files += 1
                    names.setdefault(e, []).append(rel)
                    with open(path, encoding="utf-8", errors="replace") as f:
                        lines = sum(1 for _ in f)
                    if lines > a.max_file_lines:
                        big_files.append((lines, rel))
                    for name, first, length in measure(path):
                        if length > a.max_function_lines:
                            big_functions.append((length, f"{rel}:{first}", name))
    repeated = {n: p for n, p in names.items() if len(p) > 1 and n != "__init__.py"}
    print(f"{files} files; over {a.max_file_lines} lines: {len(big_files)}; functions over "
          f"{a.max_function_lines} lines: {len(big_functions)}; file names used twice: {len(repeated)}")
    if a.list:
        for lines, rel in sorted(big_files, reverse=True):
            print(f"  file {rel}: {lines} lines")
        for length, where, name in sorted(big_functions, reverse=True):
            print(f"  function {where} {name}: {length} lines")
        for n, p in sorted(repeated.items()):
            print(f"  name {n}: {', '.join(p)}")
    if not a.known:
        return 1 if big_files or big_functions or repeated else 0
    known = {}
    for line in open(a.known):
        parts = line.split("#")[0].split()
        if parts:
            known[tuple(parts[:-1])] = int(parts[-1])
    found = {("file", rel): lines for lines, rel in big_files}
    for length, where, name in big_functions:
        key = ("function", where.split(":")[0], name)
        found[key] = max(found.get(key, 0), length)
    bad = [f"{' '.join(k)}: {v} lines, not in {a.known}" for k, v in found.items() if k not in known]
    bad += [f"{' '.join(k)}: {v} lines, grew from {known[k]}" for k, v in found.items()
            if k in known and v > known[k]]
    bad += [f"name {n} used {len(p)} times: {', '.join(p)}" for n, p in sorted(repeated.items())]
    for k in sorted(set(known) - set(found)):
        print(f"  no longer over the limit (remove from {a.known}): {' '.join(k)}")
    for b in sorted(bad):
        print(f"  NEW: {b}")
    print(f"known offenders left: {len(set(known) & set(found))}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
