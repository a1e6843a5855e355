#!/usr/bin/env python3
"""Generates studioctl's sample printers from idl/studio.idl (run by the build; the output stays in
the build tree and is never committed).

For every struct of the IDL it writes print_<Struct>(Printer&, const studio_<Struct>&) that visits
each member by its IDL name (arrays as arrays, enums by name, nested structs as objects), a key
function (the @key members joined by '/'), and a table of the structs that have a topic
descriptor (every struct idlc makes one for: all but @nested ones, or only the @topic ones when
any struct is annotated @topic). A construct this script does not know
stops the build with the IDL line, so a new IDL type can never be silently unprintable.

usage: gen_printers.py studio.idl OUT.h OUT.cc
"""
import re
import sys

PRIMITIVES = {
    # IDL type -> C++ type of the idlc C mapping
    "boolean": "bool", "octet": "uint8_t", "char": "char", "int8": "int8_t", "uint8": "uint8_t",
    "int16": "int16_t", "uint16": "uint16_t", "short": "int16_t", "int32": "int32_t",
    "uint32": "uint32_t", "long": "int32_t", "int64": "int64_t", "uint64": "uint64_t",
    "float": "float", "double": "double",
}

TOKEN = re.compile(r"\s*(?:(//[^\n]*|/\*.*?\*/)|(@\w+(?:\([^)]*\))?)|([A-Za-z_]\w*)|(\d+)|(\"[^\"]*\")|(.))",
                   re.S)


class IdlError(Exception):
    pass


def tokenize(text):
    out = []
    pos = 0
    while pos < len(text):
        m = TOKEN.match(text, pos)
        if not m or m.end() == pos:
            break
        tok = m.group(0).strip()
        if tok and not m.group(1):
            out.append((tok, text.count("\n", 0, m.end()) + 1))
        pos = m.end()
    return out


class Parser:
    def __init__(self, tokens):
        self.t = tokens
        self.i = 0
        self.enums = {}     # name -> [enumerators]
        self.structs = []   # (name, [member dict])
        self.struct_names = set()
        self.nested = set()
        self.topics = set()
        self.scope = []     # enclosing modules
        self.c_name = {}    # IDL name -> C name (idlc: modules joined by '_')

    def peek(self):
        return self.t[self.i][0] if self.i < len(self.t) else None

    def line(self):
        return self.t[min(self.i, len(self.t) - 1)][1]

    def next(self):
        tok = self.t[self.i][0]
        self.i += 1
        return tok

    def expect(self, tok):
        got = self.next()
        if got != tok:
            raise IdlError(f"line {self.line()}: expected '{tok}', got '{got}'")

    def parse(self):
        while self.peek() is not None:
            self.definition()

    def definition(self):
        annotations = []
        while self.peek() and self.peek().startswith("@"):
            annotations.append(self.next())
        kw = self.next()
        if kw == "module":
            self.scope.append(self.next())
            self.expect("{")
            while self.peek() != "}":
                self.definition()
            self.expect("}")
            self.expect(";")
            self.scope.pop()
        elif kw == "enum":
            name = self.next()
            self.expect("{")
            values = []
            while self.peek() != "}":
                values.append(self.next())
                if self.peek() == ",":
                    self.next()
            self.expect("}")
            self.expect(";")
            self.enums[name] = values
            prefix = "".join(m + "_" for m in self.scope)
            self.c_name[name] = prefix + name
            for v in values:
                self.c_name[name + "::" + v] = prefix + v
        elif kw == "const":
            while self.next() != ";":
                pass
        elif kw == "struct":
            name = self.next()
            self.expect("{")
            members = []
            while self.peek() != "}":
                members.append(self.member())
            self.expect("}")
            self.expect(";")
            self.structs.append((name, members))
            self.struct_names.add(name)
            self.c_name[name] = "".join(m + "_" for m in self.scope) + name
            # idlc makes no topic descriptor for a @nested struct (nor, once any struct says
            # @topic, for the others): those are printed only inside their parents.
            if "@nested" in annotations or any(a.startswith("@nested(TRUE") for a in annotations):
                self.nested.add(name)
            if any(a == "@topic" or a.startswith("@topic(") for a in annotations):
                self.topics.add(name)
        else:
            raise IdlError(f"line {self.line()}: studioctl's printer generator does not know '{kw}'")

    def type_spec(self):
        tok = self.next()
        if tok == "string":
            if self.peek() == "<":
                self.next()
                bound = int(self.next())
                self.expect(">")
                return {"kind": "string", "bound": bound}
            return {"kind": "string", "bound": None}
        if tok == "sequence":
            self.expect("<")
            elem = self.type_spec()
            if self.peek() == ",":
                self.next()
                self.next()
            self.expect(">")
            return {"kind": "sequence", "elem": elem}
        if tok in ("unsigned", "long") and self.peek() in ("long", "short"):
            raise IdlError(f"line {self.line()}: use the fixed-width IDL types (int64, uint32, ...)")
        if tok in PRIMITIVES:
            return {"kind": "primitive", "ctype": PRIMITIVES[tok], "idl": tok}
        if tok in self.enums:
            return {"kind": "enum", "name": tok}
        if tok in self.struct_names:
            return {"kind": "struct", "name": tok}
        raise IdlError(f"line {self.line()}: studioctl's printer generator does not know type '{tok}'")

    def member(self):
        annotations = []
        while self.peek().startswith("@"):
            annotations.append(self.next())
        ty = self.type_spec()
        name = self.next()
        dims = []
        while self.peek() == "[":
            self.next()
            dims.append(int(self.next()))
            self.expect("]")
        self.expect(";")
        if len(dims) > 1:
            raise IdlError(f"line {self.line()}: multi-dimensional arrays are not supported ({name})")
        return {"name": name, "type": ty, "dims": dims, "key": "@key" in annotations}


def emit_value(ty, expr, out, indent):
    pad = "  " * indent
    k = ty["kind"]
    if k == "primitive":
        if ty["idl"] == "octet":
            out.append(f"{pad}p.number(uint64_t({expr}));")
        elif ty["idl"] == "char":
            out.append(f"{pad}p.string(&{expr}, 1);")
        else:
            out.append(f"{pad}p.number({expr});")
    elif k == "string":
        if ty["bound"] is None:
            out.append(f"{pad}p.string({expr} ? {expr} : \"\", SIZE_MAX);")
        else:
            out.append(f"{pad}p.string({expr}, sizeof({expr}));")
    elif k == "enum":
        # The stored value as an integer: a sample may hold a value outside the enum (a bad or a
        # newer writer), and loading that as the enum type is undefined (UBSan: -fsanitize=enum).
        out.append(f"{pad}p.enumeration(enum_name_{ty['name']}(enum_value({expr})), "
                   f"enum_value({expr}));")
    elif k == "struct":
        out.append(f"{pad}p.begin_object();")
        out.append(f"{pad}print_{ty['name']}(p, {expr});")
        out.append(f"{pad}p.end_object();")
    else:
        raise IdlError("nested sequences are not supported")


def emit_array(ty, count_expr, elem_expr, out):
    structured = "true" if ty["kind"] == "struct" else "false"
    bulky = "true" if ty["kind"] == "primitive" and ty["idl"] == "octet" else "false"
    out.append(f"  {{")
    out.append(f"    const std::size_t n = {count_expr};")
    out.append(f"    const std::size_t shown = p.begin_array(n, {structured}, {bulky});")
    out.append(f"    for (std::size_t i = 0; i < shown; ++i) {{")
    out.append(f"      p.element();")
    emit_value(ty, elem_expr, out, 3)
    out.append(f"    }}")
    out.append(f"    p.end_array(n, shown);")
    out.append(f"  }}")


def generate(parser, idl_path):
    h = [
        "// Generated by deploy/studioctl/gen_printers.py from " + idl_path + ". Do not edit.",
        "#pragma once",
        "#include <span>",
        "#include <string>",
        "#include \"studio.h\"",
        "#include \"studioctl/printer.h\"",
        "namespace studio::ctl {",
        "// One row per IDL struct: its IDL name, descriptor, printer and key.",
        "struct IdlType {",
        "  const char* name;  // IDL name without the module, e.g. \"AlphaMask\"",
        "  const dds_topic_descriptor_t* descriptor;",
        "  void (*print)(Printer& p, const void* sample);  // the members, inside an open object",
        "  std::string (*key)(const void* sample);          // @key members joined by '/'",
        "};",
        "std::span<const IdlType> idl_types();",
        "}  // namespace studio::ctl",
    ]
    c = [
        "// Generated by deploy/studioctl/gen_printers.py from " + idl_path + ". Do not edit.",
        "#include \"studioctl_types.h\"",
        "#include <cstdint>",
        "#include <cstring>",
        "#include <array>",
        "namespace studio::ctl {",
        "namespace {",
        "// An idlc enum member's bytes as the 32-bit integer they are.",
        "template <class E>",
        "int64_t enum_value(const E& e) {",
        "  static_assert(sizeof(E) == sizeof(int32_t));",
        "  int32_t v;",
        "  std::memcpy(&v, &e, sizeof v);",
        "  return v;",
        "}",
    ]
    for name, values in parser.enums.items():
        c.append(f"const char* enum_name_{name}(int64_t v) {{")
        c.append("  switch (v) {")
        for v in values:
            c.append(f"    case {parser.c_name[name + '::' + v]}: return \"{v}\";")
        c.append("  }")
        c.append("  return nullptr;")
        c.append("}")
    for name, _ in parser.structs:
        c.append(f"void print_{name}(Printer& p, const {parser.c_name[name]}& s);")
    for name, members in parser.structs:
        c.append(f"void print_{name}(Printer& p, const {parser.c_name[name]}& s) {{")
        for m in members:
            c.append(f"  p.key(\"{m['name']}\");")
            ty = m["type"]
            if m["dims"]:
                emit_array(ty, str(m["dims"][0]), f"s.{m['name']}[i]", c)
            elif ty["kind"] == "sequence":
                emit_array(ty["elem"], f"s.{m['name']}._length",
                           f"s.{m['name']}._buffer[i]", c)
            else:
                emit_value(ty, f"s.{m['name']}", c, 1)
        c.append("}")
        keys = [m for m in members if m["key"]]
        c.append(f"std::string key_{name}(const void* v) {{")
        c.append(f"  [[maybe_unused]] const auto& s = *static_cast<const {parser.c_name[name]}*>(v);")
        c.append("  std::string k;")
        for i, m in enumerate(keys):
            if i:
                c.append("  k += '/';")
            if m["type"]["kind"] == "string" and not m["dims"]:
                c.append(f"  k += Printer::bounded(s.{m['name']}, sizeof(s.{m['name']}));")
            else:
                c.append(f"  k += std::to_string(s.{m['name']});")
        c.append("  return k;")
        c.append("}")
    c.append("}  // namespace")
    with_descriptor = [name for name, _ in parser.structs
                       if name not in parser.nested and (not parser.topics or name in parser.topics)]
    c.append(f"constexpr std::array<IdlType, {len(with_descriptor)}> kTypes{{{{")
    for name in with_descriptor:
        cn = parser.c_name[name]
        c.append(f"  {{\"{name}\", &{cn}_desc, [](Printer& p, const void* s) "
                 f"{{ print_{name}(p, *static_cast<const {cn}*>(s)); }}, &key_{name}}},")
    c.append("}};")
    c.append("std::span<const IdlType> idl_types() { return kTypes; }")
    c.append("}  // namespace studio::ctl")
    return "\n".join(h) + "\n", "\n".join(c) + "\n"


def main():
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    idl, out_h, out_c = sys.argv[1:]
    with open(idl, encoding="utf-8") as f:
        text = f.read()
    parser = Parser(tokenize(text))
    try:
        parser.parse()
    except IdlError as e:
        print(f"{idl}: {e}", file=sys.stderr)
        return 1
    h, c = generate(parser, "idl/studio.idl")
    for path, body in ((out_h, h), (out_c, c)):
        try:
            with open(path, encoding="utf-8") as f:
                if f.read() == body:
                    continue
        except OSError:
            pass
        with open(path, "w", encoding="utf-8") as f:
            f.write(body)
    return 0


if __name__ == "__main__":
    sys.exit(main())
