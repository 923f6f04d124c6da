#!/usr/bin/python3
"""ROS 2 .msg definitions -> ROS 2 IDL, with Debian's rosidl_adapter.

    msg_to_idl.py [--dds-names] --msg-dir DIR --out-dir OUT PKG/Name...

Writes OUT/PKG/msg/Name.idl for each PKG/Name from DIR/PKG/msg/Name.msg: the IDL that every
ROS 2 build makes from its .msg files (rosidl_adapter's msg.idl.em), which fastddsgen -typeros2
compiles under the type names rmw_fastrtps registers (PKG::msg::dds_::Name_).

--dds-names: the same types as plain DDS IDL under those names (PKG::msg::dds_::Name_, as
rmw_cyclonedds registers them too), for an IDL compiler without a ROS 2 mode (Cyclone's
idlc): annotations and the constants modules left out, which change nothing on the wire.

DIR is a msgdefs/ros2<distro> folder of the npm package @foxglove/rosmsg-msgs-common. Its
files hold the upstream .msg text followed by the definitions it depends on, each after a
line of '=' and `MSG: pkg/Name` (gendeps2's format); only the text before the first such line
is the message's own.
"""
import argparse
import contextlib
import os
import pathlib
import re
import sys
import tempfile

from rosidl_adapter.msg import convert_msg_to_idl

GENDEPS_SEPARATOR = re.compile(r'^={10,}\s*$', re.MULTILINE)


def own_definition(text):
    return GENDEPS_SEPARATOR.split(text, maxsplit=1)[0]


@contextlib.contextmanager
def stdout_silenced():
    """rosidl_adapter prints each file it reads and writes. empy replaces sys.stdout with a
    proxy of its own, so the file descriptor is redirected, not the Python object."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, 'w') as devnull:
            os.dup2(devnull.fileno(), 1)
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


ANNOTATION = re.compile(r'@\w+\s*\((?:[^()"]|"(?:[^"\\]|\\.)*")*\)\s*')
QUALIFIED = re.compile(r'\b(\w+)::msg::(\w+)\b')


def block_end(text, open_brace):
    """The index after the '};' that closes the block whose '{' is at open_brace."""
    depth = 0
    for i in range(open_brace, len(text)):
        if text[i] == '{':
            depth += 1
        elif text[i] == '}':
            depth -= 1
            if depth == 0:
                return text.index(';', i) + 1
    raise ValueError('unbalanced braces')


def dds_names(idl):
    """rosidl's IDL -> the same structs as PKG::msg::dds_::Name_."""
    idl = ANNOTATION.sub('', idl)
    while (m := re.search(r'module \w+_Constants\s*{', idl)):
        idl = idl[:m.start()] + idl[block_end(idl, m.end() - 1):]
    idl = QUALIFIED.sub(r'\1::msg::dds_::\2_', idl)
    m = re.search(r'struct (\w+)\s*{', idl)
    if not m:
        raise ValueError('no struct')
    end = block_end(idl, m.end() - 1)
    return (idl[:m.start()] + 'module dds_ {\n' + f'struct {m.group(1)}_ ' + idl[m.end() - 1:end] + '\n};' +
            idl[end:])


def convert(msg_dir, out_dir, work_dir, package, name, dds):
    source = msg_dir / package / 'msg' / f'{name}.msg'
    package_dir = work_dir / package
    (package_dir / 'msg').mkdir(parents=True, exist_ok=True)
    (package_dir / 'msg' / source.name).write_text(
        own_definition(source.read_text(encoding='utf-8')), encoding='utf-8')
    idl_dir = out_dir / package / 'msg'
    idl_dir.mkdir(parents=True, exist_ok=True)
    with stdout_silenced():
        convert_msg_to_idl(package_dir, package, pathlib.Path('msg') / source.name, idl_dir)
    if dds:
        idl = idl_dir / f'{name}.idl'
        idl.write_text(dds_names(idl.read_text(encoding='utf-8')), encoding='utf-8')


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--dds-names', action='store_true')
    parser.add_argument('--msg-dir', required=True, type=pathlib.Path)
    parser.add_argument('--out-dir', required=True, type=pathlib.Path)
    parser.add_argument('types', nargs='+', metavar='PKG/Name')
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as work:
        for type_name in args.types:
            package, slash, name = type_name.partition('/')
            if not slash or not package or not name or '/' in name:
                print(f'msg_to_idl: {type_name}: expected PKG/Name', file=sys.stderr)
                return 2
            try:
                convert(args.msg_dir, args.out_dir, pathlib.Path(work), package, name, args.dds_names)
            except Exception as error:  # rosidl_adapter raises plain exceptions on bad input
                print(f'msg_to_idl: {type_name}: {error}', file=sys.stderr)
                return 1
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
