"""The package's own surface (issue 41): ``lobe.__version__`` is the Rust
workspace's version, ``dir(lobe)`` shows lobe's names and not the modules
it imports, and ``Material.chooses_lobe`` is a method, as its docstring and
docs/python.md say."""

import importlib.metadata
import os
import re
import types

import lobe

_root = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def _workspace_version() -> str:
    with open(os.path.join(_root, "Cargo.toml"), encoding="utf-8") as f:
        text = f.read()
    section = text.split("[workspace.package]", 1)[1].split("\n[", 1)[0]
    m = re.search(r'^version\s*=\s*"([^"]+)"', section, re.M)
    assert m, section
    return m.group(1)


def test_version_is_the_crates_and_the_packages():
    assert isinstance(lobe.__version__, str)
    assert lobe.__version__ == _workspace_version()
    assert lobe.__version__ == importlib.metadata.version("lobe")
    assert "__version__" in dir(lobe)


def test_dir_shows_only_lobes_names():
    names = dir(lobe)
    public = [n for n in names if not (n.startswith("__") and n.endswith("__"))]
    assert sorted(public) == sorted(lobe.__all__)
    for n in public:
        assert hasattr(lobe, n), n
    # No module that lobe imports, under any name, and no typing helper.
    for n in public:
        v = getattr(lobe, n)
        assert not isinstance(v, types.ModuleType) or v.__name__.startswith("lobe."), n
    for n in ("np", "numpy", "os", "json", "Mapping", "Any", "Sequence", "annotations", "_lobe"):
        assert n not in names, n
    assert "Material" in names and "render" in names and "chi2" in names


def test_chooses_lobe_is_a_method():
    two = lobe.load_dict({"type": "cook-torrance", "alpha": 0.3, "kd": 0.2})
    one = lobe.load_dict({"type": "cook-torrance", "alpha": 0.3})
    assert callable(two.chooses_lobe)
    assert two.chooses_lobe("vndf") is True and one.chooses_lobe("vndf") is False
    assert two.chooses_lobe() is True
    doc = lobe.Material.chooses_lobe.__doc__ or ""
    assert "A method" in doc, doc
    with open(os.path.join(_root, "docs", "python.md"), encoding="utf-8") as f:
        text = f.read()
    assert re.search(r"`m\.chooses_lobe\(strategy\)` (are|is a) methods?", text), "docs/python.md"
