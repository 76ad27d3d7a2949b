"""The type stubs name every class and method the extension module has, and no other."""

import ast
import pathlib

import seam
import seam._seam as ext

STUBS = pathlib.Path(seam.__file__).with_name("_seam.pyi")


def stub_classes():
    tree = ast.parse(STUBS.read_text())
    classes = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            members = set()
            for item in node.body:
                if isinstance(item, ast.FunctionDef):
                    members.add(item.name)
                elif isinstance(item, ast.AnnAssign):
                    members.add(item.target.id)
            classes[node.name] = members
    return classes


def test_stubs_match_the_module():
    stubs = stub_classes()
    public = {n for n in dir(ext) if isinstance(getattr(ext, n), type)}
    assert public == set(stubs)
    assert set(seam.__all__) == public | {"__version__"}
    for name in public:
        cls = getattr(ext, name)
        if issubclass(cls, BaseException):
            continue
        members = {m for m in dir(cls) if not m.startswith("_")} | (
            {"__init__"} if "__init__" in stubs[name] else set()
        )
        assert members == stubs[name] - {"__len__"}, name
