#!/usr/bin/env python3
"""Lists import circles among the files of src/.

A circle is two or more files that each reach the other through `use` lines or paths in
code (`crate::a::b`, `super::x`, `self::y`). Each path is mapped to the file that defines the
module it names; a name a `mod.rs` (or `lib.rs`) only re-exports (`pub use x::Name`) is
followed to the file that defines it. Edges into a file's own ancestor `mod.rs` (its folder's
shared types; `lib.rs` for every file) are ignored, as are a file's edges to itself. The
circles are the strongly connected components of more than one file.

Usage: scripts/import_cycles.py [SRC_DIR]   (default: src). Exit status 1 if any circle.
"""

import os
import re
import sys


def strip_code(text):
    """The text with comments, strings and char literals blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "r" and re.match(r'r#*"', text[i:]) and not (i and (text[i - 1].isalnum() or text[i - 1] == "_")):
            hashes = re.match(r"r(#*)\"", text[i:]).group(1)
            end = text.find('"' + hashes, i + 2 + len(hashes))
            j = n if end < 0 else end + 1 + len(hashes)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            j += 1
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "'":
            # A char literal ('x', '\n', '\''), not a lifetime ('a).
            m = re.match(r"'(\\.[^']*|[^\\'])'", text[i:])
            if m:
                out.append(" " * len(m.group(0)))
                i += len(m.group(0))
            else:
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def expand_use(tree):
    """`a::{b, c::{d, e}}` -> [[a, b], [a, c, d], [a, c, e]] (renames and globs kept as the path)."""
    tree = re.sub(r"\s+as\s+\w+", "", tree)
    tree = re.sub(r"\s+", "", tree)

    def split_top(s):
        parts, depth, cur = [], 0, ""
        for ch in s:
            if ch == "{":
                depth += 1
            elif ch == "}":
                depth -= 1
            if ch == "," and depth == 0:
                parts.append(cur)
                cur = ""
            else:
                cur += ch
        if cur:
            parts.append(cur)
        return parts

    def walk(s):
        b = s.find("{")
        if b < 0:
            return [[p for p in s.split("::") if p]]
        head = [p for p in s[:b].split("::") if p]
        inner = s[b + 1 : s.rfind("}")]
        res = []
        for part in split_top(inner):
            for tail in walk(part):
                res.append(head + tail)
        return res

    return walk(tree)


class Crate:
    def __init__(self, root_dir, root_file):
        self.root_dir = root_dir
        self.root_file = root_file
        self.modules = {}  # module path tuple -> file
        self.files = {}  # file -> module path tuple
        self.reexports = {}  # file -> {name: (module tuple of the file, path segments)}

    def module_of(self, path):
        rel = os.path.relpath(path, self.root_dir)
        if path == self.root_file:
            return ()
        parts = rel[:-3].split(os.sep)
        if parts[-1] == "mod":
            parts = parts[:-1]
        return tuple(parts)


def inline_modules(code):
    """(start, end, name) of each inline `mod name { … }` in stripped code."""
    found = []
    for m in re.finditer(r"\bmod\s+(\w+)\s*\{", code):
        depth, j = 1, m.end()
        while j < len(code) and depth:
            if code[j] == "{":
                depth += 1
            elif code[j] == "}":
                depth -= 1
            j += 1
        found.append((m.end(), j, m.group(1)))
    return found


def module_at(base, mods, pos):
    path = list(base)
    for start, end, name in mods:
        if start <= pos < end:
            path.append(name)
    return tuple(path)


USE_RE = re.compile(r"\b(?:pub(?:\([^)]*\))?\s+)?use\s+([^;]+);")
PATH_RE = re.compile(r"(?<![\w:])((?:crate|super|self)(?:\s*::\s*\w+)+)")


def resolve(crate, here, segs, depth=0):
    """The file the path `segs` (used in module `here`) names, or None if outside the crate."""
    if not segs:
        return None
    if segs[0] == "crate":
        mod, rest = [], segs[1:]
    elif segs[0] in ("super", "self"):
        mod, rest = list(here), list(segs)
        while rest and rest[0] in ("super", "self"):
            if rest[0] == "super" and mod:
                mod.pop()
            rest = rest[1:]
    else:
        return None
    # Longest prefix that is a module.
    mod = tuple(mod)
    while rest and mod + (rest[0],) in crate.modules:
        mod, rest = mod + (rest[0],), rest[1:]
    while mod not in crate.modules:  # an inline module: its file
        mod = mod[:-1]
    target = crate.modules[mod]
    if rest and depth < 8:
        ex = crate.reexports.get(target, {}).get(rest[0])
        if ex:
            ex_mod, ex_segs = ex
            followed = resolve(crate, ex_mod, ex_segs, depth + 1)
            if followed:
                return followed
    return target


def scan(src):
    crates = []
    lib = Crate(src, os.path.join(src, "lib.rs"))
    crates.append(lib)
    bins = os.path.join(src, "bin")
    for dirpath, _, names in os.walk(src):
        for name in sorted(names):
            if not name.endswith(".rs"):
                continue
            path = os.path.join(dirpath, name)
            if path.startswith(bins + os.sep):
                continue
            m = lib.module_of(path)
            lib.modules[m] = path
            lib.files[path] = m
    if os.path.isdir(bins):
        for entry in sorted(os.listdir(bins)):
            d = os.path.join(bins, entry)
            if os.path.isdir(d) and os.path.exists(os.path.join(d, "main.rs")):
                c = Crate(d, os.path.join(d, "main.rs"))
                for dirpath, _, names in os.walk(d):
                    for name in sorted(names):
                        if name.endswith(".rs"):
                            path = os.path.join(dirpath, name)
                            c.modules[c.module_of(path)] = path
                            c.files[path] = c.module_of(path)
                crates.append(c)
    edges = {}  # (from, to) -> first line
    for crate in crates:
        codes = {}
        for path, base in crate.files.items():
            with open(path, encoding="utf-8") as f:
                code = strip_code(f.read())
            mods = inline_modules(code)
            codes[path] = (code, mods)
            for start, end, name in mods:
                m = module_at(base, mods, start)
                crate.modules.setdefault(m, path)
            # Re-exports of a mod.rs / lib.rs / main.rs.
            if path.endswith(("mod.rs", "lib.rs", "main.rs")):
                ex = {}
                for u in re.finditer(r"\bpub(?:\([^)]*\))?\s+use\s+([^;]+);", code):
                    here = module_at(base, mods, u.start())
                    for segs in expand_use(u.group(1)):
                        if segs and segs[-1] != "*":
                            full = segs if segs[0] in ("crate", "super", "self") else ["self"] + segs
                            ex[segs[-1]] = (here, full)
                crate.reexports[path] = ex
        for path, (code, mods) in codes.items():
            base = crate.files[path]
            found = []
            for u in USE_RE.finditer(code):
                here = module_at(base, mods, u.start())
                for segs in expand_use(u.group(1)):
                    if segs and segs[0] not in ("crate", "super", "self"):
                        # `use books::State;` after `mod books;` or a sibling through a re-export.
                        if here + (segs[0],) in crate.modules:
                            segs = ["self"] + segs
                    segs = [s for s in segs if s not in ("*",)]
                    found.append((u.start(), here, segs))
            for p in PATH_RE.finditer(code):
                here = module_at(base, mods, p.start())
                segs = re.sub(r"\s+", "", p.group(1)).split("::")
                found.append((p.start(), here, segs))
            for pos, here, segs in found:
                target = resolve(crate, here, segs)
                if not target or target == path:
                    continue
                tmod = crate.files[target]
                is_folder_root = target.endswith(("mod.rs", "lib.rs", "main.rs"))
                if is_folder_root and base[: len(tmod)] == tmod:
                    continue  # the source's own ancestor mod.rs
                line = code.count("\n", 0, pos) + 1
                edges.setdefault((path, target), line)
    return edges


def tarjan(nodes, succ):
    index, low, on, stack, out = {}, {}, set(), [], []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in succ.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(nodes):
        if v not in index:
            visit(v)
    return out


def main():
    src = sys.argv[1] if len(sys.argv) > 1 else "src"
    edges = scan(src)
    succ, nodes = {}, set()
    for a, b in edges:
        succ.setdefault(a, []).append(b)
        nodes.update((a, b))
    for v in succ:
        succ[v].sort()
    comps = [c for c in tarjan(nodes, succ) if len(c) > 1]
    if not comps:
        print(f"no import circle among the files of {src}/ ({len(edges)} edges)")
        return 0
    print(f"{len(comps)} import circle(s) among the files of {src}/:")
    for comp in sorted(comps):
        members = set(comp)
        print(f"- {len(comp)} files: " + ", ".join(os.path.relpath(f, src) for f in comp))
        for (a, b), line in sorted(edges.items()):
            if a in members and b in members:
                print(f"    {os.path.relpath(a, src)}:{line} -> {os.path.relpath(b, src)}")
    return 1


if __name__ == "__main__":
    sys.exit(main())
