"""Shared fixtures: the repository, the command-line binary the results are compared with."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]

# The package and the command line are compared to the last bit, which holds at equal thread
# counts only: the parallel kernels (factorisation, products) split their sums by thread, so
# another count changes the round-off, and on a friction branch round-off can move the points.
# The command line's default follows the machine's load; fix the count for both, before the
# package starts its thread pool.
os.environ["RAYON_NUM_THREADS"] = "2"


def cli_binary() -> pathlib.Path:
    """The `stickslip` binary: $STICKSLIP_BIN, else the newest of target/{release,debug}."""
    if os.environ.get("STICKSLIP_BIN"):
        return pathlib.Path(os.environ["STICKSLIP_BIN"])
    found = [ROOT / "target" / p / "stickslip" for p in ("release", "debug")]
    found = [p for p in found if p.exists()]
    if not found:
        pytest.fail("no stickslip binary: run `cargo build -p stickslip-cli` (or set STICKSLIP_BIN)")
    return max(found, key=lambda p: p.stat().st_mtime)


@pytest.fixture(scope="session")
def root() -> pathlib.Path:
    return ROOT


@pytest.fixture(scope="session")
def cli():
    binary = cli_binary()

    def run(*args, check=True):
        p = subprocess.run([str(binary), *map(str, args)], capture_output=True, text=True)
        if check and p.returncode != 0:
            raise AssertionError(f"stickslip {' '.join(map(str, args))} failed:\n{p.stderr}")
        return p

    return run
