"""Shared helpers of the Python package's tests: the `rastergi` binary they check against
(RASTERGI_BIN, else this checkout's target/release/rastergi) and how to run it."""

import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def _binary() -> str:
    path = os.environ.get("RASTERGI_BIN") or str(REPO / "target" / "release" / "rastergi")
    if not Path(path).is_file():
        pytest.exit(f"no rastergi binary at {path}: build it (cargo build --release) or set RASTERGI_BIN", 2)
    return path


class Cli:
    """Runs the command line `rastergi` in a directory."""

    def __init__(self, binary: str, cwd: Path):
        self.binary, self.cwd = binary, cwd

    def run(self, *args: str) -> subprocess.CompletedProcess:
        return subprocess.run([self.binary, *args], cwd=self.cwd, capture_output=True, text=True, timeout=300)

    def ok(self, *args: str) -> str:
        r = self.run(*args)
        assert r.returncode == 0, f"rastergi {' '.join(args)} failed:\n{r.stderr}"
        return r.stdout

    def error(self, *args: str) -> str:
        """The message of a run that fails: its one error line without "error: "."""
        r = self.run(*args)
        assert r.returncode != 0, f"rastergi {' '.join(args)} succeeded"
        lines = [l for l in r.stderr.splitlines() if l.startswith("error: ") and "XDG_RUNTIME_DIR" not in l]
        assert lines, r.stderr
        return lines[0][len("error: "):]


@pytest.fixture
def cli(tmp_path: Path) -> Cli:
    return Cli(_binary(), tmp_path)
