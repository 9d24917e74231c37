"""Tests of scripts/bench-peer.py, the scipy peer of `bench fit`: it solves the
C++ fit's problem (same projection masks, unknowns and rel_mse to 1e-9
relative) and fails loudly when the problem differs. CTest entry
"python: scipy peer" (python/CMakeLists.txt); the CLI is $BF_CLI_PATH, else
build/experiments/brdf-factor."""
import json
import os
import pathlib
import runpy
import subprocess
import sys

import pytest

HERE = pathlib.Path(__file__).resolve().parent
PEER = HERE / "bench-peer.py"


def cli_path():
    return os.environ.get("BF_CLI_PATH") or str(HERE.parent / "build" / "experiments" / "brdf-factor")


def run_peer(*args):
    cli = cli_path()
    assert os.access(cli, os.X_OK), "brdf-factor CLI not found at %s (set BF_CLI_PATH)" % cli
    return subprocess.run([sys.executable, str(PEER), "--cli", cli, *args], capture_output=True, text=True)


@pytest.mark.parametrize("extra", [
    ["--texture", "8"],                                           # W1's fit, small: 2 random wiwo terms
    ["--texture", "8", "--seed", "7", "--parameterization", "halfdiff"],
    ["--texture", "5", "--terms", "3"],                           # a fixed first term, taken off the targets
    ["--texture", "3", "--seed", "2"],
])
def test_peer_agrees_with_the_cpp_fit(extra):
    p = run_peer("--check", "--grid", "8", *extra)
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout.strip().splitlines()[-1])
    # The check itself compares masks, unknowns and rel_mse; the figures are
    # asserted here too, so that a silently weakened check is seen.
    assert out["samples"] > 0 and out["unknowns"] > 0
    assert 0 < out["rel_mse_cpp"] < 1
    assert abs(out["rel_mse_peer"] - out["rel_mse_cpp"]) <= 1e-9 * out["rel_mse_cpp"]
    assert out["rel_diff"] <= 1e-9


def test_peer_fails_loudly_on_a_different_problem():
    # Smoothing 0.1% off: same masks and unknowns, a rel_mse about 2e-5 away.
    p = run_peer("--check", "--grid", "8", "--texture", "8", "--perturb-smoothing", "1.001")
    assert p.returncode == 1
    assert p.stdout == ""
    assert "bench-peer: FAILED: check: rel_mse: C++ " in p.stderr
    assert "relative difference" in p.stderr and "> 1e-09" in p.stderr


def test_peer_refuses_what_it_does_not_implement(tmp_path):
    peer = runpy.run_path(str(PEER), run_name="bench_peer")
    dump = tmp_path / "input.json"
    d = subprocess.run([cli_path(), "bench", "fit", "--grid", "4", "--texture", "4", "--repeats", "1",
                        "--reciprocity", "--dump-input", str(dump)], capture_output=True, text=True)
    assert d.returncode == 0, d.stderr
    with pytest.raises(peer["PeerError"], match=r"terms\[0\]\.reciprocal: the peer supports non-reciprocal"):
        peer["load_input"](str(dump))
    j = json.loads(dump.read_text())
    j["format"] = "something else"
    dump.write_text(json.dumps(j))
    with pytest.raises(peer["PeerError"], match=r"format: expected 'brdf-factor bench-fit input 1', found"):
        peer["load_input"](str(dump))


def test_dump_input_refuses_a_path_it_cannot_write(tmp_path):
    bad = tmp_path / "no such folder" / "input.json"
    p = subprocess.run([cli_path(), "bench", "fit", "--grid", "4", "--texture", "4", "--repeats", "1",
                        "--dump-input", str(bad)], capture_output=True, text=True)
    assert p.returncode == 2
    assert "--dump-input: cannot open '%s' for writing" % bad in p.stderr
    assert p.stdout == ""  # refused before the benchmark ran
