#!/usr/bin/python3
"""The wire layout of the contract's IDL types, and the check that it changes only with the
contract's major version.

  idl_layout.py dump FILE...
      Every struct and enum of FILE... (they may refer to each other's types) in a normalised
      form: names without the version module, types spelled one way, bounds evaluated.
  idl_layout.py check --idl-dir IDL --versions-dir VERSIONS --contract N [--converted HEADER]
      (a) the types of IDL/*.idl are in module vN, and VERSIONS/vN exists;
      (b) every type of VERSIONS/vN has the same layout in IDL (types may be added);
      (c) every type of VERSIONS/vN-1 has the same layout in VERSIONS/vN, but those the service
          converts: the service's option to serve contract N-1 as well writes vN's types under
          vN-1's names and converts the others. HEADER (C++) names them in its list
          `kConvertedTypes[] = {"Status", ...}` (dds/include/pmu/dds/previous_contract.hpp);
          a name there that is no type of vN-1 is a finding too.

Exit status: 0 all hold (one summary line), 1 findings (one a line), 2 bad usage or IDL this
checker does not understand (file:line). The types are @final / XCDR1, so the layout is the
members in order with their types, bounds and keys, and each enum's literals in order.

Parsed with the IDL 4.2 grammar of Debian's python3-rosidl (only its lark tree is used).
"""
import argparse
import functools
import pathlib
import re
import sys

try:
    from lark import Token, Tree
    from lark.exceptions import UnexpectedInput
    from rosidl_parser.parser import get_ast_from_idl_string
except ImportError as e:  # run by another interpreter, or the package is missing
    print(f"idl_layout: {e}: needs Debian's python3-rosidl under /usr/bin/python3 "
          "(scripts/setup.sh test installs it)", file=sys.stderr)
    sys.exit(2)

VERSION_MODULE = re.compile(r"v(\d+)$")
ARRAY_DIMS = re.compile(r"(.*?)((?:\[\d+\])*)$")

BASE_TYPES = {
    "signed_tiny_int": "int8", "signed_short_int": "short", "signed_long_int": "long",
    "signed_longlong_int": "long long", "unsigned_tiny_int": "uint8",
    "unsigned_short_int": "unsigned short", "unsigned_long_int": "unsigned long",
    "unsigned_longlong_int": "unsigned long long", "floating_pt_type_float": "float",
    "floating_pt_type_double": "double", "floating_pt_type_long_double": "long double",
    "char_type": "char", "wide_char_type": "wchar", "boolean_type": "boolean",
    "octet_type": "octet",
}
BINARY_OPERATORS = {
    "or_expr": ("|",), "xor_expr": ("^",), "and_expr": ("&",), "shift_expr": ("<<", ">>"),
    "add_expr": ("+", "-"), "mult_expr": ("*", "/", "%"),
}
# Extensibility decides the encoding for the vendors that honour it, and their defaults
# differ, so it is compared as written (no annotation is not the same as @final).
EXTENSIBILITY = ("final", "appendable", "mutable")


class IdlError(Exception):
    """IDL this checker does not understand: exit 2."""


def _tokens(tree):
    return list(tree.scan_values(lambda v: isinstance(v, Token)))


def _line(tree, default):
    tokens = _tokens(tree)
    return tokens[0].line if tokens else default


def _trunc_div(a, b):
    q = abs(a) // abs(b)
    return q if (a < 0) == (b < 0) else -q


class Member:
    def __init__(self, name, type_, key, line):
        self.name, self.type, self.key, self.line = name, type_, key, line

    def text(self):
        return ("@key " if self.key else "") + f"{self.type} {self.name}"


class Type:
    """A struct or enum; `name` is the scoped name without the version module."""

    def __init__(self, kind, name, version, file, line, annotation=None):
        self.kind, self.name, self.version = kind, name, version
        self.file, self.line, self.annotation = file, line, annotation
        self.members = []   # struct: Member; enum: (literal, line)

    def layout(self):
        if self.kind == "enum":
            return ("enum", tuple(name for name, _ in self.members))
        return ("struct", self.annotation,
                tuple((m.name, m.type, m.key) for m in self.members))

    def dump(self):
        head = (f"@{self.annotation} " if self.annotation else "") + f"{self.kind} {self.name}"
        if self.kind == "enum":
            return "\n".join([head] + [f"  {name}" for name, _ in self.members])
        return "\n".join([head] + [f"  {m.text()}" for m in self.members])


@functools.lru_cache(maxsize=None)
def _parse(text):
    return get_ast_from_idl_string(text)


class Idl:
    """The types of a set of IDL files that may refer to each other."""

    def __init__(self, paths):
        self.types = {}        # name without the version module -> Type
        self._decls = {}       # full scoped name (tuple) -> (kind, node, scope, file)
        self._consts = {}      # full scoped name -> int
        self._typedefs = {}    # full scoped name -> normalised type
        self._resolving = set()
        self._texts = {}
        self.modules = []      # (file, line, N) of each module vN
        structs = []
        for path in paths:
            path = str(path)
            try:
                text = pathlib.Path(path).read_text(encoding="utf-8")
            except (OSError, UnicodeDecodeError) as e:
                raise IdlError(f"{path}: {e}") from None
            try:
                tree = _parse(text)
            except UnexpectedInput as e:
                first = str(e).strip().splitlines()[0]
                raise IdlError(f"{path}:{e.line}:{e.column}: not IDL this checker parses: {first}") from None
            self._texts[path] = text
            self._collect(tree.children, (), path, structs)
        for full in [f for f, d in self._decls.items() if d[0] == "const"]:
            self._const(full)
        for full, node, scope, path in structs:
            self._struct(full, node, scope, path)

    # Declarations.
    def _err(self, path, line, what):
        raise IdlError(f"{path}:{line}: {what}")

    def _no_annotations(self, node, path, where):
        for child in node.children:
            if isinstance(child, Tree) and child.data == "annotation_appl":
                name = "::".join(t.value for t in _tokens(child.children[0]))
                self._err(path, _line(child, "?"), f"annotation @{name} on {where}: not understood")

    def _declare(self, full, kind, node, scope, path, line):
        if full in self._decls:
            self._err(path, line, f"{'::'.join(full)} declared twice")
        self._decls[full] = (kind, node, scope, path)

    def _collect(self, definitions, scope, path, structs):
        for definition in definitions:
            node = definition.children[0]
            if node.data == "include_directive":
                continue   # every file of the set is read; a type from elsewhere is unresolved
            line = _line(node, "?")
            if node.data == "module_dcl":
                self._no_annotations(node, path, "a module")
                name = next(c for c in node.children if isinstance(c, Token))
                if VERSION_MODULE.match(name.value):
                    self.modules.append((path, name.line, int(name.value[1:])))
                self._collect([c for c in node.children if isinstance(c, Tree) and c.data == "definition"],
                              scope + (name.value,), path, structs)
            elif node.data == "const_dcl":
                self._no_annotations(node, path, "a constant")
                name = next(c for c in node.children if isinstance(c, Token))
                self._declare(scope + (name.value,), "const", node, scope, path, name.line)
            elif node.data == "type_dcl" and node.children[0].data == "typedef_dcl":
                self._typedef(node.children[0].children[0], scope, path)
            elif node.data == "type_dcl":
                decl = node.children[0].children[0]   # constr_type_dcl -> struct_dcl | enum_dcl
                if decl.data == "enum_dcl":
                    self._enum(decl, scope, path)
                elif decl.children[0].data == "struct_def":
                    struct = decl.children[0]
                    name = next(c for c in struct.children if isinstance(c, Token))
                    full = scope + (name.value,)
                    self._declare(full, "struct", struct, scope, path, name.line)
                    structs.append((full, struct, scope, path))
                elif decl.children[0].data != "struct_forward_dcl":   # declares no layout
                    self._err(path, line, f"{decl.children[0].data}: not understood")
            else:
                self._err(path, line, f"{node.data}: not understood")

    def _new_type(self, kind, full, path, line, annotation=None):
        versions = [int(m.group(1)) for m in map(VERSION_MODULE.match, full[:-1]) if m]
        if len(versions) > 1:
            self._err(path, line, f"{'::'.join(full)}: more than one version module")
        name = self._stripped(full)
        if name in self.types:
            other = self.types[name]
            self._err(path, line, f"{name} also declared at {other.file}:{other.line}")
        t = Type(kind, name, versions[0] if versions else None, path, line, annotation)
        self.types[name] = t
        return t

    def _enum(self, node, scope, path):
        self._no_annotations(node, path, "an enum")
        name = next(c for c in node.children if isinstance(c, Token))
        full = scope + (name.value,)
        self._declare(full, "enum", node, scope, path, name.line)
        t = self._new_type("enum", full, path, name.line)
        for enumerator in (c for c in node.children if isinstance(c, Tree)):
            self._no_annotations(enumerator, path, "an enum literal")
            literal = _tokens(enumerator)[-1]
            t.members.append((literal.value, literal.line))
        self._unique(t, t.members)

    def _typedef(self, node, scope, path):
        spec, declarators = node.children
        if spec.data == "constr_type_dcl":
            self._err(path, _line(node, "?"), "a struct or enum declared in a typedef: not understood")
        for declarator in declarators.children:
            inner = declarator.children[0]
            name = _tokens(inner)[0]
            self._declare(scope + (name.value,), "typedef", (spec, inner), scope, path, name.line)

    def _struct(self, full, node, scope, path):
        annotation, line = None, _line(node, "?")
        for child in node.children:
            if isinstance(child, Tree) and child.data == "annotation_appl":
                annotation = self._extensibility(child, path)
        name = next(c for c in node.children if isinstance(c, Token))
        t = self._new_type("struct", full, path, name.line, annotation)
        for member in (c for c in node.children if isinstance(c, Tree) and c.data == "member"):
            key, spec, declarators = False, None, None
            for child in member.children:
                if child.data == "annotation_appl":
                    key = self._key(child, path)
                elif child.data == "type_spec":
                    spec = child
                else:
                    declarators = child
            for declarator in declarators.children:
                inner = declarator.children[0]
                ident = _tokens(inner)[0]
                t.members.append(Member(ident.value, self._declared_type(spec, inner, scope, path),
                                        key, ident.line))
        if not t.members:
            self._err(path, line, f"{t.name}: a struct without members")
        self._unique(t, [(m.name, m.line) for m in t.members])

    def _unique(self, t, names):
        seen = set()
        for name, line in names:
            if name in seen:
                self._err(t.file, line, f"{t.name}: {name} declared twice")
            seen.add(name)

    # Annotations.
    def _annotation(self, node):
        name = "::".join(t.value for t in _tokens(node.children[0]))
        params = node.children[1] if len(node.children) > 1 else None
        return name, params

    def _key(self, node, path):
        name, params = self._annotation(node)
        line = _line(node, "?")
        if name != "key":
            self._err(path, line, f"annotation @{name} on a member: not understood")
        if params is None:
            return True
        flag = [t.data for t in params.iter_subtrees() if t.data.startswith("boolean_literal_")]
        if len(flag) != 1 or len(params.children) != 1 or _tokens(params):
            self._err(path, line, "@key takes TRUE or FALSE")
        return flag[0] == "boolean_literal_true"

    def _extensibility(self, node, path):
        name, params = self._annotation(node)
        line = _line(node, "?")
        if name in EXTENSIBILITY and params is None:
            return name
        if name == "extensibility" and params is not None:
            value = [t.value for t in _tokens(params)]
            if len(value) == 1 and value[0].lower() in EXTENSIBILITY:
                return value[0].lower()
        self._err(path, line, f"annotation @{name} on a struct: not understood")

    # Types.
    def _lookup(self, scoped, scope, path, kinds, what):
        parts = [t.value for t in _tokens(scoped)]
        innermost = scoped
        while isinstance(innermost.children[0], Tree) and innermost.children[0].data == "scoped_name":
            innermost = innermost.children[0]
        absolute = isinstance(innermost.children[0], Tree)   # a leading ::
        candidates = [tuple(parts)] if absolute else [
            scope[:i] + tuple(parts) for i in range(len(scope), -1, -1)]
        for full in candidates:
            if full in self._decls:
                if self._decls[full][0] not in kinds:
                    self._err(path, _line(scoped, "?"), f"{'::'.join(parts)} is not {what}")
                return full
        self._err(path, _line(scoped, "?"), f"{'::'.join(parts)}: not declared in these files ({what} expected)")

    def _declared_type(self, spec, declarator, scope, path):
        line = _line(declarator, "?")
        dims = "".join(f"[{self._int(size.children[0], scope, path, line, True)}]"
                       for size in declarator.children[1:])
        # x[2] of a typedef long[3] is long[2][3], as if declared in one go.
        element = ARRAY_DIMS.match(self._type(spec, scope, path, line))
        return element.group(1) + dims + element.group(2)

    def _type(self, node, scope, path, line):
        while node.data in ("type_spec", "simple_type_spec", "template_type_spec", "base_type_spec",
                            "integer_type", "signed_int", "unsigned_int", "floating_pt_type"):
            node = node.children[0]
        if node.data in BASE_TYPES:
            return BASE_TYPES[node.data]
        if node.data in ("string_type", "wide_string_type"):
            word = "string" if node.data == "string_type" else "wstring"
            if not node.children:
                return word
            return f"{word}<{self._int(node.children[0], scope, path, line, True)}>"
        if node.data == "sequence_type":
            element = self._type(node.children[0], scope, path, line)
            if len(node.children) == 1:
                return f"sequence<{element}>"
            return f"sequence<{element},{self._int(node.children[1], scope, path, line, True)}>"
        if node.data == "scoped_name":
            full = self._lookup(node, scope, path, ("struct", "enum", "typedef"), "a type")
            kind, decl, decl_scope, decl_path = self._decls[full]
            if kind != "typedef":
                return self._stripped(full)
            return self._typedef_type(full, decl, decl_scope, decl_path)
        self._err(path, line, f"type {node.data}: not understood")

    def _stripped(self, full):
        return "::".join(p for p in full if not VERSION_MODULE.match(p))

    def _typedef_type(self, full, decl, scope, path):
        # An alias is the type it names: the bytes on the wire are the same.
        if full not in self._typedefs:
            spec, declarator = decl
            if full in self._resolving:
                self._err(path, _line(declarator, "?"), f"typedef {'::'.join(full)} refers to itself")
            self._resolving.add(full)
            self._typedefs[full] = self._declared_type(spec, declarator, scope, path)
        return self._typedefs[full]

    # Constant expressions.
    def _const(self, full):
        if full not in self._consts:
            _, node, scope, path = self._decls[full]
            const_type, name, expr = node.children[-3:]
            line = name.line
            t = const_type.children[0]
            if t.data not in ("integer_type", "octet_type"):
                self._err(path, line, f"constant {name.value}: only integer constants are understood")
            if full in self._resolving:
                self._err(path, line, f"constant {name.value} refers to itself")
            self._resolving.add(full)
            self._consts[full] = self._int(expr, scope, path, line, False)
        return self._consts[full]

    def _int(self, node, scope, path, line, positive):
        value = self._eval(node, scope, path, line)
        if positive and value <= 0:
            self._err(path, line, f"bound {value}: not positive")
        return value

    def _eval(self, node, scope, path, line):
        line = _line(node, line)
        kids = node.children
        if node.data in ("positive_int_const", "const_expr", "literal", "integer_literal") and len(kids) == 1:
            return self._eval(kids[0], scope, path, line)
        if node.data in BINARY_OPERATORS:
            if len(kids) == 1:
                return self._eval(kids[0], scope, path, line)
            a, b = (self._eval(k, scope, path, line) for k in kids)
            op = self._operator(node.data, kids, path, line)
            if op in ("/", "%") and b == 0:
                self._err(path, line, "division by zero in a constant expression")
            return {"|": lambda: a | b, "^": lambda: a ^ b, "&": lambda: a & b,
                    "<<": lambda: a << b, ">>": lambda: a >> b, "+": lambda: a + b,
                    "-": lambda: a - b, "*": lambda: a * b, "/": lambda: _trunc_div(a, b),
                    "%": lambda: a - b * _trunc_div(a, b)}[op]()
        if node.data == "unary_expr":
            value = self._eval(kids[-1], scope, path, line)
            if len(kids) == 1:
                return value
            op = kids[0].children[0].data
            return {"unary_operator_minus": -value, "unary_operator_plus": value,
                    "unary_operator_tilde": ~value}[op]
        if node.data == "primary_expr":
            if kids[0].data == "scoped_name":
                return self._const(self._lookup(kids[0], scope, path, ("const",), "a constant"))
            return self._eval(kids[0], scope, path, line)
        digits = "".join(t.value for t in _tokens(node))
        base = {"decimal_literal": 10, "octal_literal": 8, "hexadecimal_literal": 16}.get(node.data)
        if base is None:
            self._err(path, line, f"{node.data} in a constant expression: only integers are understood")
        return int(digits, base)

    def _operator(self, rule, kids, path, line):
        # The grammar drops operator tokens: the operator is the source text between the
        # operands, less comments, blanks and closing parentheses.
        text = self._texts[path]
        between = text[_tokens(kids[0])[-1].end_pos:_tokens(kids[1])[0].start_pos]
        between = re.sub(r"//[^\n]*|/\*.*?\*/", " ", between, flags=re.S).lstrip(" \t\r\n)")
        for op in BINARY_OPERATORS[rule]:
            if between.startswith(op):
                return op
        self._err(path, line, f"operator of {rule}: not understood")


# The check.
def _where(path, line):
    return f"{path}:{line}" if line else path


def compare(old, new, old_label, new_label):
    """Findings (path, line, type, text) for each type of `old` whose layout `new` lacks."""
    findings = []
    for name, o in sorted(old.types.items()):
        n = new.types.get(name)
        if n is None:
            findings.append((o.file, o.line, name, f"removed ({o.kind} of {old_label}, not in {new_label})"))
            continue
        if o.layout() == n.layout():
            continue
        found = []
        if o.kind != n.kind:
            found.append((n.line, f"a {o.kind} in {old_label}, a {n.kind} in {new_label}"))
        elif o.kind == "enum":
            found += _list_changes("literal", o.members, n.members, o, n, old_label, new_label)
        else:
            if o.annotation != n.annotation:
                found.append((n.line, f"extensibility {_ann(o)} in {old_label}, {_ann(n)} in {new_label}"))
            found += _list_changes("member", [(m.name, m.line) for m in o.members],
                                   [(m.name, m.line) for m in n.members], o, n, old_label, new_label)
            olds = {m.name: m for m in o.members}
            for m in n.members:
                p = olds.get(m.name)
                if p and p.type != m.type:
                    found.append((m.line, f"member {m.name}: {p.type} in {old_label}, {m.type} in {new_label}"))
                if p and p.key != m.key:
                    found.append((m.line, f"member {m.name}: @key {'dropped' if p.key else 'added'} "
                                          f"({p.text()} in {old_label}, {m.text()} in {new_label})"))
        for line, text in found or [(n.line, "layout differs")]:
            findings.append((n.file, line, name, text))
    return findings


def _ann(t):
    return f"@{t.annotation}" if t.annotation else "none written"


def _list_changes(what, old, new, o, n, old_label, new_label):
    old_names, new_names = [x for x, _ in old], [x for x, _ in new]
    found = []
    for x, line in new:
        if x not in old_names:
            found.append((line, f"{what} {x} added at position {new_names.index(x) + 1} "
                                f"(not in {old_label})"))
    for x, _ in old:
        if x not in new_names:
            found.append((n.line, f"{what} {x} removed (in {old_label} at {_where(o.file, dict(old)[x])})"))
    common_old = [x for x in old_names if x in new_names]
    common_new = [x for x in new_names if x in old_names]
    if common_old != common_new:
        first = next(i for i, (a, b) in enumerate(zip(common_old, common_new)) if a != b)
        found.append((dict(new)[common_new[first]], f"{what}s reordered: {', '.join(common_old)} in "
                      f"{old_label}; {', '.join(common_new)} in {new_label}"))
    return found


def _idl_files(directory):
    files = sorted(pathlib.Path(directory).glob("*.idl"))
    if not files:
        raise IdlError(f"{directory}: no .idl files")
    return [str(f) for f in files]


def _frozen(directory, version, findings):
    idl = Idl(_idl_files(directory))
    for path, line, module in idl.modules:
        if module != version:
            findings.append((path, line, None, f"module v{module}, but {directory} keeps contract {version}"))
    return idl


CONVERTED_LIST = re.compile(r"kConvertedTypes\[\]\s*=\s*\{([^}]*)\}")


def converted_types(header):
    """The names (pmu::Status, ...) of the C++ list kConvertedTypes[] = {"Status", ...} of `header`."""
    try:
        text = pathlib.Path(header).read_text()
    except OSError as e:
        raise IdlError(f"{header}: {e.strerror}")
    m = CONVERTED_LIST.search(text)
    if not m:
        raise IdlError(f"{header}: no list kConvertedTypes[] = {{...}} of the types the service converts")
    names = re.findall(r'"([^"]*)"', m.group(1))
    for name in names:
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
            raise IdlError(f"{header}:{text[:m.start()].count(chr(10)) + 1}: kConvertedTypes: {name!r} is not a type name")
    return {"pmu::" + name for name in names}


def check(idl_dir, versions_dir, n, converted=frozenset(), converted_from=None):
    findings = []
    current = Idl(_idl_files(idl_dir))
    # (a)
    for path, line, module in current.modules:
        if module != n:
            findings.append((path, line, None, f"module v{module}, but the contract version is {n} "
                             f"(cmake/install_dirs.cmake PMU_CONTRACT_VERSION): the IDL's module must be v{n}"))
    for t in sorted(current.types.values(), key=lambda t: t.name):
        if t.version is None:
            findings.append((t.file, t.line, t.name, f"outside a version module: the IDL's module must be v{n}"))
    frozen_dir = pathlib.Path(versions_dir) / f"v{n}"
    if not frozen_dir.is_dir():
        findings.append((str(frozen_dir), None, None,
                         f"missing: it keeps contract {n}'s IDL as published, a copy of {idl_dir}/*.idl"))
        return findings, [], None
    # (b)
    frozen = _frozen(frozen_dir, n, findings)
    changed = compare(frozen, current, f"v{n}", str(idl_dir))
    hints = []
    if changed:
        findings += changed
        hints.append(f"{len({f[2] for f in changed})} type(s) of contract {n} changed layout: bump the contract's "
                     f"major version (cmake/install_dirs.cmake PMU_CONTRACT_VERSION {n + 1}, the IDL's module "
                     f"v{n + 1}), keep the new IDL in {pathlib.Path(versions_dir) / f'v{n + 1}'} and {frozen_dir} "
                     f"as it is, and say it in docs/interface.md section 10")
    # (c)
    if n > 1:
        previous_dir = pathlib.Path(versions_dir) / f"v{n - 1}"
        if not previous_dir.is_dir():
            findings.append((str(previous_dir), None, None,
                             f"missing: serving contract {n - 1} as well is checked against it"))
        else:
            previous = _frozen(previous_dir, n - 1, findings)
            for name in sorted(converted - set(previous.types)):
                findings.append((converted_from, None, name, f"named in kConvertedTypes, but contract {n - 1} "
                                 f"has no such type ({previous_dir})"))
            differ = [f for f in compare(previous, frozen, f"v{n - 1}", f"v{n}") if f[2] not in converted]
            findings += differ
            for name in sorted({f[2] for f in differ}):
                hints.append(f"{name}: contract {n} does not have contract {n - 1}'s layout, so serving "
                             f"contract {n - 1} as well (v{n}'s types under v{n - 1}'s names) needs a converter "
                             f"for {name} (dds/src/previous_contract.cpp), named in kConvertedTypes"
                             + (f" of {converted_from}" if converted_from else ""))
    previous = ""
    if n > 1:
        kept = f"; contract {n - 1}'s types keep their layout in it"
        previous = kept + (f" but the converted {', '.join(sorted(converted))}" if converted else "")
    summary = (f"idl layout: {idl_dir} (module v{n}, {len(current.types)} types) keeps the "
               f"{len(frozen.types)} types of {frozen_dir}{previous}")
    return findings, hints, summary


def main(argv=None):
    parser = argparse.ArgumentParser(prog="idl_layout.py", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    verbs = parser.add_subparsers(dest="verb", required=True)
    dump = verbs.add_parser("dump", help="print the normalised layout of every type of FILE...")
    dump.add_argument("files", nargs="+", metavar="FILE")
    chk = verbs.add_parser("check", help="the IDL's layout against the published contract versions")
    chk.add_argument("--idl-dir", required=True, metavar="IDL", help="the current IDL (idl)")
    chk.add_argument("--versions-dir", required=True, metavar="VERSIONS",
                     help="the published IDL, one vN per major version")
    chk.add_argument("--contract", required=True, type=int, metavar="N", help="the contract's major version N")
    chk.add_argument("--converted", metavar="HEADER",
                     help="the C++ header whose kConvertedTypes lists the types of contract N-1 the service converts")
    args = parser.parse_args(argv)
    try:
        if args.verb == "dump":
            idl = Idl(args.files)
            print("\n".join(t.dump() for _, t in sorted(idl.types.items())))
            return 0
        if args.contract < 1:
            parser.error("--contract: a major version is 1 or more")
        converted = converted_types(args.converted) if args.converted else frozenset()
        findings, hints, summary = check(args.idl_dir, args.versions_dir, args.contract, converted, args.converted)
    except IdlError as e:
        print(f"idl_layout: {e}", file=sys.stderr)
        return 2
    for path, line, name, text in findings:
        print(f"{_where(path, line)}: " + (f"{name}: " if name else "") + text)
    for hint in hints:
        print(hint)
    if not findings:
        print(summary)
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
