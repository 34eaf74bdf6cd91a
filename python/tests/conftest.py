import os
import shutil
import sys

import pytest

# Test the installed package, never the sources in python/.
_src = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
sys.path = [p for p in sys.path if os.path.abspath(p or ".") != _src]

_root = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


@pytest.fixture(scope="session")
def lobe_exe():
    """The `lobe` binary to compare with: $LOBE_BIN, else the newest of the
    workspace's target/{debug,release}/lobe (bash .ci/test, the README's test command, builds
    target/debug/lobe before pytest runs), else `lobe` on PATH."""
    env = os.environ.get("LOBE_BIN")
    if env:
        if not os.path.exists(env):
            pytest.fail(f"LOBE_BIN={env}: no such file")
        return env
    built = [p for p in (os.path.join(_root, "target", d, "lobe") for d in ("debug", "release")) if os.path.exists(p)]
    if built:
        return max(built, key=os.path.getmtime)
    exe = shutil.which("lobe")
    if exe is None:
        pytest.skip("no lobe binary to compare with (cargo build -p lobe-cli, or set LOBE_BIN)")
    return exe
