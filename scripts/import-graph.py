#!/usr/bin/env python3
"""File-level import graph of a Rust module tree (src/gpu, src/geom), cycles reported.

Every `super::…`, `crate::…` path in code (use statements with brace groups expanded, and
inline paths like `super::font::glyph_rows()`) is resolved to the file that defines it;
paths through a mod.rs re-export (`pub use x::Y`) resolve to x's file. Comments and doc
links are ignored; mod.rs's own `mod`/`pub use` lines are the facade, not edges.
Usage: scripts/import-graph.py src gpu   (exit status 1 when there is a circle)
       scripts/import-graph.py src       (the top-level modules: which imports which)
"""
import os, re, sys

root = sys.argv[1]
top = sys.argv[2] if len(sys.argv) > 2 else None   # e.g. src gpu

def mod_files():
    out = {}
    base = os.path.join(root, top)
    for dp, _, fs in os.walk(base):
        for f in fs:
            if not f.endswith('.rs'):
                continue
            rel = os.path.relpath(os.path.join(dp, f), root)[:-3].split(os.sep)
            if rel[-1] == 'mod':
                rel = rel[:-1]
            out[tuple(rel)] = os.path.join(dp, f)
    return out

def top_level():
    """Top-level module -> the top-level modules its files name through `crate::`."""
    names = {f[:-3] if f.endswith('.rs') else f for f in os.listdir(root)
             if f not in ('lib.rs', 'main.rs') and (f.endswith('.rs') or
                                                    os.path.isdir(os.path.join(root, f)))}
    g = {n: set() for n in names}
    for n in names:
        base = os.path.join(root, n)
        files = [base + '.rs'] if os.path.isfile(base + '.rs') else [
            os.path.join(dp, f) for dp, _, fs in os.walk(base) for f in fs if f.endswith('.rs')]
        for f in files:
            src = strip_comments(open(f).read())
            paths = [e for m in re.finditer(r'\buse\s+([^;]+);', src) for e in expand(m.group(1))]
            paths += re.findall(r'\bcrate::\w+', src)
            for p in paths:
                segs = p.replace(' ', '').split('::')
                if len(segs) > 1 and segs[0] == 'crate' and segs[1] in names and segs[1] != n:
                    g[n].add(segs[1])
    return g

if top is None:
    MODS = {}
else:
    MODS = mod_files()

def strip_comments(s):
    s = re.sub(r'/\*.*?\*/', '', s, flags=re.S)
    s = re.sub(r'//[^\n]*', '', s)
    s = re.sub(r'"(?:\\.|[^"\\])*"', '""', s)
    return s

def expand(tree):
    """'a::{b::C, d}' -> ['a::b::C', 'a::d']"""
    tree = tree.strip()
    i = tree.find('{')
    if i < 0:
        return [re.sub(r'\s+as\s+\w+$', '', tree)]
    prefix, inner = tree[:i], tree[i + 1:tree.rfind('}')]
    parts, depth, cur = [], 0, ''
    for ch in inner:
        if ch == ',' and depth == 0:
            parts.append(cur); cur = ''; continue
        depth += ch == '{'; depth -= ch == '}'
        cur += ch
    parts.append(cur)
    res = []
    for p in parts:
        if p.strip():
            for e in expand(p):
                res.append(prefix + e if e != 'self' else prefix.rstrip(':'))
    return res

def reexports(mod):
    """name -> absolute path (tuple) for `pub use` in mod's file."""
    src = strip_comments(open(MODS[mod]).read())
    out = {}
    for m in re.finditer(r'pub(?:\([^)]*\))?\s+use\s+([^;]+);', src):
        for p in expand(m.group(1)):
            segs = p.replace(' ', '').split('::')
            out[segs[-1]] = absolute(mod, segs)
    return out

def absolute(mod, segs):
    cur = list(mod)
    segs = list(segs)
    if segs[0] == 'crate':
        cur = []; segs = segs[1:]
    elif segs[0] == 'self':
        segs = segs[1:]
    elif segs[0] == 'super':
        while segs and segs[0] == 'super':
            cur = cur[:-1]; segs = segs[1:]
    else:
        # relative to current module (child module or external crate)
        if tuple(cur + [segs[0]]) in MODS:
            pass
        else:
            return None
    return tuple(cur + segs)

def resolve(path, seen=0):
    """absolute path -> defining file's module key, or None if outside the tree."""
    if path is None or seen > 10:
        return None
    if path[:1] != (top,):
        return None
    cur = (top,)
    for i, s in enumerate(path[1:], 1):
        if s == '*':
            return cur
        if cur + (s,) in MODS:
            cur = cur + (s,)
            continue
        rx = reexports(cur)
        if s in rx:
            return resolve(rx[s] + path[i + 1:], seen + 1)
        return cur
    return cur

def inline_mods(src):
    """(start, end) offsets of inline `mod name { … }` blocks."""
    out = []
    for m in re.finditer(r'\bmod\s+\w+\s*\{', src):
        d, i = 1, m.end()
        while d and i < len(src):
            d += src[i] == '{'; d -= src[i] == '}'; i += 1
        out.append((m.end(), i))
    return out

def edges():
    g = {m: set() for m in MODS}
    for mod, f in MODS.items():
        src = strip_comments(open(f).read())
        is_modrs = f.endswith('mod.rs')
        paths = []
        blocks = inline_mods(src)
        depth = lambda pos: sum(1 for a, b in blocks if a <= pos < b)
        for m in re.finditer(r'(pub(?:\([^)]*\))?\s+)?use\s+([^;]+);', src):
            if is_modrs and m.group(1) and m.group(1).strip().startswith('pub'):
                continue  # facade re-export
            paths += [(e, depth(m.start())) for e in expand(m.group(2))]
        src_nouse = re.sub(r'\buse\s+[^;]+;', lambda m: ' ' * len(m.group(0)), src)
        paths += [(m.group(0), depth(m.start()))
                  for m in re.finditer(r'\b(?:crate|super)(?:::(?:super|\w+))+', src_nouse)]
        for p, k in paths:
            segs = p.replace(' ', '').split('::')
            # an inline `mod tests { use super::*; }` refers k levels up within this file
            if segs[0] == 'crate':
                k = 0
            while k and segs and segs[0] == 'super':
                segs = segs[1:]; k -= 1
            if k or not segs:
                continue
            if segs[0] not in ('crate', 'super', 'self') and k == 0 and (tuple(mod) + (segs[0],)) not in MODS:
                continue
            if segs[0] not in ('crate', 'super', 'self') and (tuple(mod) + (segs[0],)) not in MODS:
                continue
            tgt = resolve(absolute(mod, segs))
            if tgt and tgt != mod and not (tgt == mod[:len(tgt)] and len(tgt) < len(mod) and False):
                g[mod].add(tgt)
    return g

def sccs(g):
    idx, low, st, on, out, n = {}, {}, [], set(), [], [0]
    sys.setrecursionlimit(10000)
    def visit(v):
        idx[v] = low[v] = n[0]; n[0] += 1; st.append(v); on.add(v)
        for w in g[v]:
            if w not in idx:
                visit(w); low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], idx[w])
        if low[v] == idx[v]:
            comp = []
            while True:
                w = st.pop(); on.discard(w); comp.append(w)
                if w == v: break
            out.append(comp)
    for v in g:
        if v not in idx: visit(v)
    return out

if top is None:
    name = lambda m: m
    g = top_level()
else:
    name = lambda m: '/'.join(m[1:]) or 'mod'
    g = edges()
for m in sorted(g):
    print(f"{name(m):22} -> {', '.join(sorted(name(t) for t in g[m]))}")
cyc = [c for c in sccs(g) if len(c) > 1]
print()
if cyc:
    for c in cyc:
        print("CYCLE:", ', '.join(sorted(name(m) for m in c)))
    sys.exit(1)
print("acyclic: no import circles")
