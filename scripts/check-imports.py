#!/usr/bin/env python3
"""No import circle between the files of a crate.

For every crate of the workspace, each source file's references to items of the same crate
(`use crate::…`, `use super::…`, `use child::…`, and paths such as `crate::a::b(…)` in code)
are resolved to the file that defines the item, following `pub use` re-exports. A file that
only re-exports (`pub use child::X`) does not depend on `child` for that: a facade is not a
dependency. The script prints every strongly connected set of more than one file and exits 1
when there is one.

Usage: scripts/check-imports.py [crate dir …]   (default: every crate of the workspace)
"""

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ITEM = r"(?:pub(?:\([^)]*\))?\s+)?(?:unsafe\s+|async\s+|const\s+|extern\s+\"C\"\s+)*"
DEF_KINDS = r"(?:fn|struct|enum|trait|type|const|static|union|mod)"


def strip(text):
    """The source without comments, strings and char literals (kept as blanks)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    i += 1
        elif c == "r" and re.match(r'r#*"', text[i:i + 10]) and not re.match(r"\w", text[i - 1:i] or " "):
            hashes = re.match(r'r(#*)"', text[i:]).group(1)
            end = text.find('"' + hashes, i + 2 + len(hashes))
            i = n if end < 0 else end + 1 + len(hashes)
            out.append('""')
        elif c == '"':
            i += 1
            while i < n and text[i] != '"':
                i += 2 if text[i] == "\\" else 1
            i += 1
            out.append('""')
        elif c == "'" and (re.match(r"'(\\.|[^\\'])'", text[i:i + 4]) or re.match(r"'\\u\{[0-9a-fA-F]+\}'", text[i:i + 12])):
            m = re.match(r"'(\\u\{[0-9a-fA-F]+\}|\\.|[^\\'])'", text[i:])
            i += len(m.group(0))
            out.append("' '")
        else:
            out.append(c)
            i += 1
    return "".join(out)


def drop_inline_modules(src):
    """The source without inline `mod name { … }` blocks (unit tests mostly): their `super::`
    is this file, and what a test module uses is no dependency of the file's code."""
    while True:
        m = re.search(r"\bmod\s+\w+\s*\{", src)
        if not m:
            return src
        depth, i = 0, m.end() - 1
        while i < len(src):
            depth += src[i] == "{"
            depth -= src[i] == "}"
            i += 1
            if depth == 0:
                break
        src = src[:m.start()] + src[i:]


class Module:
    def __init__(self, path, file, parent):
        self.path, self.file, self.parent = path, file, parent
        self.children = {}
        self.src = drop_inline_modules(strip(file.read_text())) if file else ""


def load_tree(root_file, path=()):
    """The module tree of a crate root (lib.rs, main.rs or a bin)."""
    mods = {}

    def walk(mod):
        mods[mod.path] = mod
        for m in re.finditer(r"(#\[path\s*=\s*\"([^\"]+)\"\]\s*)?(?:#\[[^\]]*\]\s*)*" + ITEM + r"mod\s+(\w+)\s*;", mod.src):
            name = m.group(3)
            if m.group(2):
                continue  # a file shared by #[path]: not this crate's tree
            here = mod.file.parent if mod.file.name in ("lib.rs", "main.rs", "mod.rs") or mod.parent is None \
                else mod.file.parent / mod.file.stem
            for cand in (here / f"{name}.rs", here / name / "mod.rs"):
                if cand.exists():
                    child = Module(mod.path + (name,), cand, mod)
                    mod.children[name] = child
                    walk(child)
                    break

    walk(Module(path, root_file, None))
    return mods


def use_paths(src):
    """Every path of every `use` statement, expanded, with whether it is a `pub use`."""
    out = []
    for m in re.finditer(r"(?:^|[;{}\]\s])(pub(?:\([^)]*\))?\s+)?use\s+([^;]+);", src):
        public = bool(m.group(1))
        for p in expand(re.sub(r"\s+", "", m.group(2))):
            out.append((p, public))
    return out


def expand(tree):
    """`a::{b, c::{d, e}}` → ['a::b', 'a::c::d', 'a::c::e']."""
    depth = 0
    brace = tree.find("{")
    if brace < 0:
        return [re.sub(r"\bas\w+$", "", tree.split(" as ")[0])] if tree else []
    prefix, inner = tree[:brace], tree[brace + 1:tree.rfind("}")]
    parts, cur = [], ""
    for ch in inner:
        depth += ch == "{"
        depth -= ch == "}"
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += ch
    parts.append(cur)
    res = []
    for part in parts:
        if not part:
            continue
        for sub in expand(part):
            res.append(prefix + sub if sub != "self" else prefix.rstrip(":"))
    return res


def defines(mod, name):
    return re.search(r"(?:^|\s)" + ITEM + DEF_KINDS + r"\s+" + re.escape(name) + r"\b", mod.src) or \
        re.search(r"macro_rules!\s*" + re.escape(name) + r"\b", mod.src)


def resolve(mods, mod, segs, seen=None):
    """The file that defines the item `segs` names, starting at module `mod`; None if external."""
    seen = seen or set()
    cur, used = descend(mods, mod, segs)
    first, segs = used == 0, segs[used:]
    if not segs:
        return cur.file
    if first and mod.path == cur.path and segs[0] not in cur.children:
        # A first segment that is neither crate/super/self nor a child: an external crate, a
        # local name, or an item imported into this file — only an item of this file counts.
        return None
    name = segs[0]
    if name == "*":
        return cur.file
    if defines(cur, name):
        return cur.file
    key = (cur.path, name)
    if key in seen:
        return cur.file
    seen.add(key)
    for p, _ in use_paths(cur.src):
        parts = p.split("::")
        if parts[-1] == name or p.endswith(f" as {name}"):
            target = resolve(mods, cur, parts, seen)
            return target or cur.file
    for p, _ in use_paths(cur.src):
        if p.endswith("::*"):
            target_mod = walk_mod(mods, cur, p.split("::")[:-1])
            if target_mod and defines(target_mod, name):
                return target_mod.file
    return cur.file


def descend(mods, mod, segs):
    """The module the leading segments of a path name (crate, super, self, child modules), and
    how many segments that took."""
    cur = mod
    for i, s in enumerate(segs):
        if s == "crate" and i == 0:
            cur = mods[()]
        elif s == "super" and cur.parent is not None:
            cur = cur.parent
        elif s == "self":
            pass
        elif s in cur.children:
            cur = cur.children[s]
        else:
            return cur, i
    return cur, len(segs)


def walk_mod(mods, mod, segs):
    """The module `segs` names in full, or None."""
    cur, used = descend(mods, mod, segs)
    return cur if used == len(segs) else None


WHY = {}


def edges(mods):
    g = {}
    for mod in mods.values():
        deps = set()
        body = re.sub(r"(?:^|[;{}\]\s])(pub(?:\([^)]*\))?\s+)?use\s+[^;]+;", " ", mod.src)
        for p, public in use_paths(mod.src):
            if public:
                continue
            parts = p.split("::")
            t = resolve(mods, mod, parts)
            if t is not None and t != mod.file:
                deps.add(t)
                WHY.setdefault((mod.file, t), p)
        for m in re.finditer(r"(?<![\w:])((?:crate|super|self)(?:::\w+)+)", body):
            t = resolve(mods, mod, m.group(1).split("::"))
            if t is not None and t != mod.file:
                deps.add(t)
                WHY.setdefault((mod.file, t), m.group(1))
        for m in re.finditer(r"(?<![\w:])(\w+)::(\w+)", body):
            if m.group(1) in mod.children:
                t = resolve(mods, mod, [m.group(1), m.group(2)])
                if t is not None and t != mod.file:
                    deps.add(t)
                    WHY.setdefault((mod.file, t), m.group(0))
        g[mod.file] = deps
    return g


def cycles(g):
    """Tarjan's strongly connected components with more than one file."""
    index, low, on, stack, out, counter = {}, {}, set(), [], [], [0]
    sys.setrecursionlimit(10000)

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in g.get(v, ()):
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
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in list(g):
        if v not in index:
            visit(v)
    return out


def crates():
    for toml in sorted(ROOT.glob("**/Cargo.toml")):
        d = toml.parent
        if any(part in ("target", ".venv", "node_modules") or part.startswith(".") for part in d.relative_to(ROOT).parts):
            continue
        if (d / "src").is_dir():
            yield d


def main():
    dirs = [Path(a).resolve() for a in sys.argv[1:]] or list(crates())
    bad = 0
    for d in dirs:
        roots = [f for f in (d / "src" / "lib.rs", d / "src" / "main.rs") if f.exists()]
        roots += sorted((d / "src" / "bin").glob("*.rs")) if (d / "src" / "bin").is_dir() else []
        for root in roots:
            mods = load_tree(root)
            g = edges(mods)
            for comp in cycles(g):
                bad += 1
                names = [str(f.relative_to(ROOT)) for f in comp]
                print(f"import circle in {d.relative_to(ROOT)}: " + " ↔ ".join(names))
                for a in comp:
                    for b in sorted(g[a] & set(comp)):
                        print(f"    {a.relative_to(d / 'src')} → {b.relative_to(d / 'src')}  ({WHY[(a, b)]})")
    if bad:
        print(f"{bad} import circle(s): move the shared item to where both can import it")
        return 1
    print(f"no import circle in {len(dirs)} crates")
    return 0


if __name__ == "__main__":
    sys.exit(main())
