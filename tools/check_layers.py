#!/usr/bin/env python3
"""The layer arrow of archgram as a build fact: core -> io -> store -> app -> net -> main.

Fails (exit 1), naming file and line or archive member and symbol, when
  (a) a source file under server/ includes a header of a layer its layer may not use, or a
      system header of a library its layer may not use;
  (b) an undefined symbol of a layer archive (build/lib/libag_<layer>.a) is defined neither
      in that layer, nor in a layer it may use, nor in one of its allowed system libraries
      (found through the compiler, read with `nm -D --defined-only`).
Entries of the allowlist file (tools/layers.allow) are reported but do not fail; an entry that
matches no violation fails, so the list only ever shrinks.

This file is the one place the matrix is written down (the README describes it).
"""
import argparse
import os
import re
import subprocess
import sys

# --- the matrix -------------------------------------------------------------------------------
# uses: layers whose headers and symbols a layer may use (whole layers).
# headers: single headers of other layers it may use (their symbols come from the object of
#          the same name, e.g. core/status.h -> status.o).
# libs: system libraries (besides libc and the compiler's runtime, allowed everywhere).
SUITESPARSE = ["m", "cholmod", "spqr", "suitesparseconfig"]
LAYERS = {
    "core": {"uses": [], "headers": [], "libs": SUITESPARSE},
    "io": {"uses": ["core"], "headers": [], "libs": SUITESPARSE + ["jansson", "yajl", "assimp", "crypto", "png"]},
    "store": {"uses": ["core", "io"], "headers": [],
              "libs": SUITESPARSE + ["jansson", "yajl", "assimp", "crypto", "png", "sqlite3", "sodium"]},
    "app": {"uses": ["core", "io", "store"], "headers": [],
            "libs": SUITESPARSE + ["jansson", "yajl", "assimp", "crypto", "png", "sqlite3", "sodium", "pthread"]},
    "net": {"uses": ["app"], "headers": ["core/status.h"],
            "libs": SUITESPARSE + ["jansson", "yajl", "assimp", "crypto", "png", "sqlite3", "sodium", "pthread", "microhttpd",
                                   "websockets"]},
}
ORDER = ["core", "io", "store", "app", "net"]
# Programs: server/main.c (archgramd) and the CLI may use every layer and library.
PROGRAMS = ["server/main.c", "server/cli.c", "server/cli/"]
# Headers outside the layer folders, and the layers whose archives hold what they declare:
# the migrations (store) and the OpenAPI document (net) compiled in by server/embed.sh.
SHARED_HEADERS = {"embedded.h": ["store", "net"]}
# System headers and the library they belong to. threads.h (C11) and the rest of libc are
# libc's; core additionally does no threads, sockets or I/O libraries (FORBIDDEN_CORE).
SYSTEM_HEADERS = [
    (re.compile(r"^jansson\.h$"), "jansson"),
    (re.compile(r"^yajl/"), "yajl"),
    (re.compile(r"^assimp/"), "assimp"),
    (re.compile(r"^openssl/"), "crypto"),
    (re.compile(r"^png\.h$|^libpng"), "png"),
    (re.compile(r"^sodium\.h$|^sodium/"), "sodium"),
    (re.compile(r"^sqlite3\.h$"), "sqlite3"),
    (re.compile(r"^pthread\.h$"), "pthread"),
    (re.compile(r"^microhttpd\.h$"), "microhttpd"),
    (re.compile(r"^libwebsockets\.h$|^lws_"), "websockets"),
    (re.compile(r"^(cholmod|SuiteSparseQR_C|SuiteSparse_config)\.h$|^suitesparse/"), "cholmod"),
]
FORBIDDEN_CORE = re.compile(r"^(threads\.h|sys/socket\.h|netinet/|arpa/inet\.h|dlfcn\.h)$")
# Defined by the linker, not by any library.
LINKER_SYMBOLS = {"_GLOBAL_OFFSET_TABLE_", "__dso_handle", "_DYNAMIC", "__ehdr_start",
                  "__executable_start", "_end", "_edata", "__bss_start"}


def allowed_libs_text(layer):
    return ", ".join(["libc"] + ["lib" + l for l in LAYERS[layer]["libs"]])


def may_use_text(layer):
    parts = LAYERS[layer]["uses"] + LAYERS[layer]["headers"]
    return ", ".join(parts) if parts else "nothing but itself"


# --- (a) includes -----------------------------------------------------------------------------

INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')


def layer_of(rel):
    """'server/net/live.c' -> 'net'; programs -> 'main'; other server files -> None."""
    for p in PROGRAMS:
        if rel == p or (p.endswith("/") and rel.startswith(p)):
            return "main"
    parts = rel.split("/")
    if len(parts) >= 3 and parts[0] == "server" and parts[1] in LAYERS:
        return parts[1]
    return None


def check_includes(root, violations):
    server = os.path.join(root, "server")
    for dirpath, _, files in os.walk(server):
        for f in sorted(files):
            if not f.endswith((".c", ".h")):
                continue
            path = os.path.join(dirpath, f)
            rel = os.path.relpath(path, root)
            layer = layer_of(rel)
            if layer is None or layer == "main":
                continue
            with open(path, encoding="utf-8", errors="replace") as fh:
                for lineno, line in enumerate(fh, 1):
                    m = INCLUDE.match(line)
                    if not m:
                        continue
                    kind, name = m.groups()
                    if kind == '"':
                        check_local_include(root, rel, lineno, layer, name, violations)
                    else:
                        check_system_include(rel, lineno, layer, name, violations)


def check_local_include(root, rel, lineno, layer, name, violations):
    target = os.path.normpath(os.path.join(os.path.dirname(rel), name))
    if not os.path.exists(os.path.join(root, target)):
        alt = os.path.normpath(os.path.join("server", name))  # -Iserver
        if os.path.exists(os.path.join(root, alt)):
            target = alt
    tparts = target.split("/")
    if len(tparts) == 2 and tparts[0] == "server" and tparts[1] in SHARED_HEADERS:
        if layer in SHARED_HEADERS[tparts[1]]:
            return
        violations.append(("include", rel, target, f"{rel}:{lineno}: includes {target}, which "
                           f"only {', '.join(SHARED_HEADERS[tparts[1]])} may use"))
        return
    tlayer = layer_of(target)
    if tlayer is None:
        violations.append(("include", rel, target,
                           f"{rel}:{lineno}: includes {target}, which is in no layer"))
        return
    if tlayer == layer or tlayer in LAYERS[layer]["uses"]:
        return
    inner = "/".join(tparts[1:])
    if inner in LAYERS[layer]["headers"]:
        return
    up = tlayer == "main" or ORDER.index(tlayer) > ORDER.index(layer)
    violations.append(("include", rel, target,
                       f"{rel}:{lineno}: includes {target} "
                       f"({tlayer}{', up the layers' if up else ''}): "
                       f"{layer} may use {may_use_text(layer)}"))


def check_system_include(rel, lineno, layer, name, violations):
    if layer == "core" and FORBIDDEN_CORE.match(name):
        violations.append(("include", rel, name, f"{rel}:{lineno}: includes <{name}>: core does "
                           "no threads, sockets or dynamic loading"))
        return
    for pattern, lib in SYSTEM_HEADERS:
        if pattern.search(name):
            if lib not in LAYERS[layer]["libs"]:
                violations.append(("include", rel, name,
                                   f"{rel}:{lineno}: includes <{name}> (lib{lib}): {layer} may "
                                   f"use {allowed_libs_text(layer)}"))
            return


# --- (b) symbols ------------------------------------------------------------------------------

def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: {r.stderr.strip()}")
    return r.stdout


def nm_archive(archive):
    """{member: (defined set, undefined set)} of a static archive."""
    members = {}
    for line in run(["nm", "-P", "-A", archive]).splitlines():
        m = re.match(r"^(.*)\[(.*)\]: (\S+) (\S)", line)
        if not m:
            continue
        _, member, sym, typ = m.groups()
        d, u = members.setdefault(member, (set(), set()))
        if typ == "U":
            u.add(sym)
        elif typ in "wv":
            continue  # weak and unresolved: optional
        else:
            d.add(sym)
    return members


def library_files(cc, name):
    """The files the linker would read for -l<name> (linker scripts followed)."""
    out = []
    for fname in (f"lib{name}.so", f"lib{name}.a"):
        p = run([cc, f"-print-file-name={fname}"]).strip()
        if os.path.isabs(p) and os.path.exists(p):
            out.extend(follow_linker_script(p))
            break
    return out


def follow_linker_script(path):
    with open(path, "rb") as fh:
        head = fh.read(4)
    if head == b"\x7fELF" or head == b"!<ar":
        return [path]
    with open(path, encoding="utf-8", errors="replace") as fh:
        text = re.sub(r"/\*.*?\*/", "", fh.read(), flags=re.S)
    files = []
    for p in re.findall(r"(/[^\s()]+)", text):
        if os.path.exists(p):
            files.extend(follow_linker_script(p))
    return files


def defined_in(path):
    if open(path, "rb").read(4) == b"!<ar":
        lines = run(["nm", "-P", "-A", "--defined-only", path]).splitlines()
        syms = set()
        for line in lines:
            m = re.match(r"^.*\]: (\S+) (\S)", line)
            if m and m.group(2) not in "Uwv":
                syms.add(m.group(1))
        return syms
    syms = set()
    for line in run(["nm", "-D", "-P", "--defined-only", path]).splitlines():
        parts = line.split()
        if parts:
            syms.add(parts[0].split("@")[0])
    return syms


def check_symbols(root, libdir, cc, violations):
    archives = {}
    for layer in ORDER:
        a = os.path.join(libdir, f"libag_{layer}.a")
        if not os.path.exists(a):
            raise RuntimeError(f"{a} is missing (build the layer archives first: make)")
        archives[layer] = nm_archive(a)
    lib_cache = {}

    def lib_syms(name):
        if name not in lib_cache:
            files = library_files(cc, name)
            if not files:
                raise RuntimeError(f"the linker finds no lib{name}")
            s = set()
            for f in files:
                s |= defined_in(f)
            lib_cache[name] = s
        return lib_cache[name]

    base = set()
    for name in ("c", "gcc_s", "gcc"):
        try:
            base |= lib_syms(name)
        except RuntimeError:
            if name == "c":
                raise
    for f in [run([cc, "-print-libgcc-file-name"]).strip()]:
        if os.path.exists(f):
            base |= defined_in(f)
    all_libs = sorted({l for v in LAYERS.values() for l in v["libs"]})

    where = {}  # symbol -> (layer, member)
    for layer in ORDER:
        for member, (d, _) in archives[layer].items():
            for s in d:
                where.setdefault(s, (layer, member))

    for layer in ORDER:
        spec = LAYERS[layer]
        ok_layers = {layer} | set(spec["uses"])
        ok_members = {}  # layer -> members allowed through single headers
        for h in spec["headers"]:
            hl, hname = h.split("/", 1)
            member = os.path.splitext(os.path.basename(hname))[0] + ".o"
            ok_members.setdefault(hl, set()).add(member)
        archive = os.path.relpath(os.path.join(libdir, f"libag_{layer}.a"), root)
        for member, (_, undef) in sorted(archives[layer].items()):
            for s in sorted(undef):
                if s in LINKER_SYMBOLS:
                    continue
                w = where.get(s)
                key = f"libag_{layer}.a({member})"
                subject = f"{archive}({member})"
                if w:
                    wl, wm = w
                    if wl in ok_layers or wm in ok_members.get(wl, set()):
                        continue
                    up = ORDER.index(wl) > ORDER.index(layer)
                    violations.append(("symbol", key, s,
                                       f"{subject}: {s} is defined in {wl} "
                                       f"({wm}{', up the layers' if up else ''}): "
                                       f"{layer} may use {may_use_text(layer)}"))
                    continue
                # libraries are read only when a symbol needs them (assimp's table is large)
                if s in base or any(s in lib_syms(l) for l in spec["libs"]):
                    continue
                owners = [l for l in all_libs if l not in spec["libs"] and s in lib_syms(l)]
                hint = f"; it is in lib{owners[0]}" if owners else ""
                violations.append(("symbol", key, s,
                                   f"{subject}: {s} is defined by no library {layer} may use "
                                   f"({allowed_libs_text(layer)}){hint}"))
        # ar keeps one member per name: two sources of one basename lose one silently
        seen = {}
        for dirpath, _, files in os.walk(os.path.join(root, "server", layer)):
            for f in files:
                if f.endswith(".c"):
                    rel = os.path.relpath(os.path.join(dirpath, f), root)
                    if f in seen:
                        violations.append(("dup", rel, f, f"{rel}: same file name as {seen[f]}: "
                                           f"one of them would be lost from libag_{layer}.a"))
                    seen[f] = rel


# --- allowlist and main -----------------------------------------------------------------------

def read_allow(path):
    entries = []
    if not path or not os.path.exists(path):
        return entries
    with open(path, encoding="utf-8") as fh:
        for lineno, line in enumerate(fh, 1):
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            if "->" not in line:
                raise RuntimeError(f"{path}:{lineno}: expected 'FILE -> HEADER' or "
                                   "'ARCHIVE(MEMBER) -> SYMBOL'")
            a, b = (x.strip() for x in line.split("->", 1))
            entries.append((a, b, lineno))
    return entries


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", default=os.path.join(os.path.dirname(__file__), ".."))
    ap.add_argument("--lib", help="folder of libag_<layer>.a (default ROOT/build/lib)")
    ap.add_argument("--allow", help="allowlist (default ROOT/tools/layers.allow)")
    ap.add_argument("--cc", default=os.environ.get("CC", "cc"))
    ap.add_argument("--includes-only", action="store_true")
    args = ap.parse_args()
    root = os.path.abspath(args.root)
    libdir = os.path.abspath(args.lib or os.path.join(root, "build", "lib"))
    allow_path = args.allow if args.allow is not None else os.path.join(root, "tools",
                                                                          "layers.allow")
    violations = []
    try:
        check_includes(root, violations)
        if not args.includes_only:
            check_symbols(root, libdir, args.cc, violations)
        allow = read_allow(allow_path)
    except (RuntimeError, OSError) as e:
        print(f"check-layers: {e}", file=sys.stderr)
        return 2
    used = set()
    failing, allowed = [], []
    for kind, subject, target, msg in violations:
        hit = [i for i, (a, b, _) in enumerate(allow) if a == subject and b == target]
        if hit:
            used.update(hit)
            allowed.append(msg)
        else:
            failing.append(msg)
    for i, (a, b, lineno) in enumerate(allow):
        if i not in used:
            failing.append(f"{os.path.relpath(allow_path, root)}:{lineno}: '{a} -> {b}' matches "
                           "no violation any more: remove it")
    for msg in failing:
        print(msg, file=sys.stderr)
    n_files = "includes" + ("" if args.includes_only else " and symbols")
    if allowed:
        print(f"check-layers: {len(allowed)} known violations allowed by "
              f"{os.path.relpath(allow_path, root)}")
    if failing:
        print(f"check-layers: {len(failing)} layer violations ({n_files} checked)",
              file=sys.stderr)
        return 1
    print(f"check-layers: ok ({n_files} of core, io, store, app, net)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
