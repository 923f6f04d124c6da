#!/usr/bin/env python3
"""Writes the `omgidl` schema of each struct of idl/*.idl as a C++ header (MCAP channels of
pmuctl record / decode --mcap, the channels of pmuctl serve; docs/interface.md 9.1).

    idl_schemas.py OUT.hpp A.idl [B.idl ...]

A struct's schema is its own definition and the definitions it uses (enums, structs,
typedefs, constants, transitively), each once, in the order of the IDL files, inside the
modules that hold them there, with the comments written above and inside them. The module
names come from the files, so nothing here names a version of the contract.
The header holds `pmu::idl_text::k_<Struct>` (std::string_view) for every struct.
Any IDL this does not understand stops the build with FILE:LINE and what was found.
"""
import re
import sys

TOKEN = re.compile(
    r"""(?P<space>\s+)|(?P<line_comment>//[^\n]*)|(?P<block_comment>/\*.*?\*/)
      |(?P<string>"(?:\\.|[^"\\])*"|'(?:\\.|[^'\\])*')
      |(?P<name>(?:::)?[A-Za-z_]\w*(?:::[A-Za-z_]\w*)*)
      |(?P<number>[0-9][\w.]*)|(?P<punct>[{}();<>,=@\[\]:+\-*/|&^~%.])""",
    re.S | re.X,
)
DEFINING = {"struct", "enum", "union", "typedef", "const", "bitmask", "bitset"}


class IdlError(Exception):
    pass


def without_preprocessor(path, text):
    """text with its preprocessor lines blanked (offsets kept); an #include stops the build."""
    lines = text.split("\n")
    for n, line in enumerate(lines):
        if line.lstrip().startswith("#"):
            if line.lstrip().lstrip("#").strip().startswith("include"):
                raise IdlError(f"{path}:{n + 1}: #include is not resolved here; inline the definitions")
            lines[n] = " " * len(line)
    return "\n".join(lines)


def tokens(path, text):
    """(kind, value, offset) of every token but spaces and comments."""
    out = []
    pos = 0
    while pos < len(text):
        m = TOKEN.match(text, pos)
        if not m:
            raise IdlError(f"{path}:{line_of(text, pos)}: unexpected {text[pos:pos + 20]!r}")
        if m.lastgroup not in ("space", "line_comment", "block_comment"):
            out.append((m.lastgroup, m.group(), pos))
        pos = m.end()
    return out


def line_of(text, offset):
    return text.count("\n", 0, offset) + 1


class Definition:
    def __init__(self, path, order, modules, kind, name, text, uses):
        self.path, self.order, self.modules = path, order, modules
        self.kind, self.name, self.text, self.uses = kind, name, text, uses

    @property
    def qualified(self):
        return "::".join(self.modules + [self.name])


def leading_start(text, start):
    """The start of the line of `start`, moved up over the comment lines right above it."""
    line_start = text.rfind("\n", 0, start) + 1
    while line_start > 0:
        prev_start = text.rfind("\n", 0, line_start - 1) + 1
        if not text[prev_start:line_start].strip().startswith("//"):
            break
        line_start = prev_start
    return line_start


def definitions(path, order_base):
    text = without_preprocessor(path, open(path, encoding="utf-8").read())
    toks = tokens(path, text)
    defs = []
    modules = []
    i = 0
    while i < len(toks):
        kind, value, offset = toks[i]
        where = f"{path}:{line_of(text, offset)}"
        if value == "module":
            if i + 2 >= len(toks) or toks[i + 1][0] != "name" or toks[i + 2][1] != "{":
                raise IdlError(f"{where}: `module` without NAME {{")
            modules.append(toks[i + 1][1])
            i += 3
            continue
        if value == "}":
            if not modules or i + 1 >= len(toks) or toks[i + 1][1] != ";":
                raise IdlError(f"{where}: unexpected }}")
            modules.pop()
            i += 2
            continue
        # One definition: tokens up to the `;` outside braces.
        j, depth = i, 0
        while j < len(toks) and not (toks[j][1] == ";" and depth == 0):
            depth += {"{": 1, "}": -1}.get(toks[j][1], 0)
            j += 1
        if j == len(toks):
            raise IdlError(f"{where}: definition without its closing ;")
        body = toks[i:j]
        words = [v for k, v, _ in body if k == "name"]
        keyword = next((w for w in words if w in DEFINING), None)
        if keyword is None or not modules:
            raise IdlError(f"{where}: not a definition inside a module: {' '.join(v for _, v, _ in body[:6])}")
        if keyword in ("struct", "enum", "union", "bitmask", "bitset"):
            name = words[words.index(keyword) + 1]
        elif keyword == "const":
            eq = [v for _, v, _ in body].index("=")
            name = body[eq - 1][1]
        else:  # typedef TYPE NAME [N]...;
            name = next(v for k, v, _ in reversed(body) if k == "name")
        end = toks[j][2] + 1
        line_end = text.find("\n", end)
        rest = text[end : line_end if line_end >= 0 else len(text)]
        if rest.strip().startswith("//"):
            end += len(rest)
        start = leading_start(text, offset)
        uses = {w.split("::")[-1] for w in words if w != name} - DEFINING
        defs.append(Definition(path, order_base + len(defs), list(modules), keyword, name, text[start:end], uses))
        i = j + 1
    if modules:
        raise IdlError(f"{path}: module {'::'.join(modules)} is not closed")
    return defs


def schema(root, by_name):
    """root's definition and those it uses, transitively, in file order, in their modules."""
    needed, todo = {}, [root]
    while todo:
        d = todo.pop()
        if d.qualified in needed:
            continue
        needed[d.qualified] = d
        for use in d.uses:
            # A name is looked up in the module of its user, as IDL scopes it.
            target = by_name.get("::".join(d.modules + [use]))
            if target is not None:
                todo.append(target)
    out = []
    current = None
    for d in sorted(needed.values(), key=lambda d: d.order):
        if d.modules != current:
            if current:
                out.append("}; " * len(current))
            out.append(" ".join(f"module {m} {{" for m in d.modules))
            current = d.modules
        out.append(d.text.rstrip("\n"))
    out.append("}; " * len(current))
    return "\n".join(line.rstrip() for line in out) + "\n"


def main(argv):
    if len(argv) < 3:
        sys.exit("usage: idl_schemas.py OUT.hpp A.idl [B.idl ...]")
    out_path, paths = argv[1], argv[2:]
    by_name = {}
    try:
        for path in paths:
            for d in definitions(path, len(by_name)):
                if d.qualified in by_name:
                    other = by_name[d.qualified]
                    raise IdlError(f"{d.path}: {d.qualified} is defined again (also in {other.path})")
                by_name[d.qualified] = d
    except IdlError as e:
        sys.exit(f"idl_schemas.py: {e}")
    structs = [d for d in by_name.values() if d.kind == "struct"]
    names = [d.name for d in structs]
    if len(set(names)) != len(names):
        sys.exit("idl_schemas.py: two structs of one name in different modules: k_<Struct> would clash")
    body = [
        "#pragma once",
        "// Generated from idl/*.idl by cmake/idl_schemas.py at build time; not committed.",
        "#include <string_view>",
        "",
        "namespace pmu::idl_text {",
        "",
    ]
    for d in structs:
        text = schema(d, by_name)
        if ")pmuidl\"" in text:
            sys.exit(f"idl_schemas.py: {d.path} contains the raw-string delimiter )pmuidl\"")
        body.append(f"// {d.qualified}")
        body.append(f'inline constexpr std::string_view k_{d.name} = R"pmuidl({text})pmuidl";')
        body.append("")
    body.append("}  // namespace pmu::idl_text")
    content = "\n".join(body) + "\n"
    try:
        with open(out_path, encoding="utf-8") as f:
            if f.read() == content:
                return
    except FileNotFoundError:
        pass
    with open(out_path, "w", encoding="utf-8") as f:
        f.write(content)


if __name__ == "__main__":
    main(sys.argv)
