"""Parameter studies: designs, schedulers, failures, the cache, the command line's shards."""

import os
import signal
import time

import numpy as np
import pandas as pd
import pytest

import stickslip

KEYS = {"joint.joint.threshold": (500.0, 2000.0), "damping.alpha": (20.0, 50.0)}


@pytest.fixture(scope="module")
def table6(root):
    """Table 6's 1-DOF study at the paper's force level only (one row per sample)."""
    study = stickslip.Study.from_toml(root / "examples" / "jenkins-1dof" / "study.toml")
    d = study.to_dict()
    d["excitation"]["levels"] = [1000.0]
    return stickslip.Study.from_dict(d, study.path)


@pytest.fixture(scope="module")
def serial(table6):
    return stickslip.run_parameters(table6, KEYS, samples=40, seed=11).to_pandas()


def test_serial_table_has_one_complete_row_per_sample(serial):
    assert list(serial["sample"]) == list(range(40))
    assert serial["error"].isna().all() and serial["complete"].all()
    # Between the stuck (238.2 Hz) and the fully slipping (190.3 Hz) resonances of Table 6.
    assert serial["peak_frequency_Hz"].between(190.0, 239.0).all()
    # A lower threshold slips more: the peak frequency rises with the threshold (Spearman
    # rank correlation close to 1 over 40 samples, damping varied too).
    rank = serial[["joint.joint.threshold", "peak_frequency_Hz"]].rank().corr().iloc[0, 1]
    assert rank > 0.9


def test_dask_local_cluster_returns_exactly_the_serial_table(table6, serial):
    out = stickslip.run_parameters(table6, KEYS, samples=40, seed=11, scheduler="dask", workers=2)
    pd.testing.assert_frame_equal(out.to_pandas(), serial, check_exact=True)


def test_local_processes_and_threads_return_exactly_the_serial_table(table6, serial):
    for scheduler in ("processes", "threads"):
        out = stickslip.run_parameters(table6, KEYS, samples=40, seed=11, scheduler=scheduler, workers=2)
        pd.testing.assert_frame_equal(out.to_pandas(), serial, check_exact=True)


def test_a_failed_sample_is_reported_and_the_others_complete(table6, serial):
    values = {k: serial[k].to_numpy().copy() for k in KEYS}
    values["joint.joint.threshold"][7] = -5.0
    out = stickslip.run_parameters(table6, values=values, scheduler="dask", workers=2).to_pandas()
    assert len(out) == 40
    bad = out[out["sample"] == 7].iloc[0]
    assert bad["error"] == '<dict>: [[joint]] "joint": threshold must be > 0 N, got -5'.replace(
        "<dict>", str(table6.path))
    good = out[out["sample"] != 7].reset_index(drop=True)
    assert good["error"].isna().all() and good["complete"].all()
    expected = serial[serial["sample"] != 7].reset_index(drop=True)
    pd.testing.assert_frame_equal(good, expected, check_exact=True)


def test_a_worker_killed_mid_run_is_replaced_and_the_table_is_identical(table6, serial):
    from dask.distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        pids = list(client.run(os.getpid).values())
        killed = []

        def progress(done, total):
            # After the first batch, kill one worker: its running and queued batches are
            # rescheduled and the nanny starts a new worker.
            if done > 0 and not killed:
                os.kill(pids[0], signal.SIGKILL)
                killed.append(done)

        out = stickslip.run_parameters(table6, KEYS, samples=40, seed=11, scheduler="dask", address=client,
                                       batch_size=2, progress=progress)
        assert killed and killed[0] < 40
    pd.testing.assert_frame_equal(out.to_pandas(), serial, check_exact=True)


def test_the_cache_resumes_and_refuses_another_study(table6, serial, tmp_path):
    cache = tmp_path / "cache"
    first = stickslip.run_parameters(table6, KEYS, samples=10, seed=11, cache=cache, curves=True)
    calls = []
    again = stickslip.run_parameters(table6, KEYS, samples=10, seed=11, cache=cache, curves=True,
                                     progress=lambda done, total: calls.append(done))
    # Every sample came from the cache: the first progress report already counts all 10.
    assert calls[0] == 10
    pd.testing.assert_frame_equal(again.to_pandas(), first.to_pandas(), check_exact=True)
    pd.testing.assert_frame_equal(again.curves(3), first.curves(3), check_exact=True)
    other = table6.to_dict()
    other["damping"]["alpha"] = 36.0
    with pytest.raises(stickslip.ParamError, match="this cache holds samples of another study"):
        stickslip.run_parameters(stickslip.Study.from_dict(other, table6.path), KEYS, samples=10, seed=11,
                                 cache=cache)


def test_curves_equal_a_direct_run(table6):
    out = stickslip.run_parameters(table6, {"joint.joint.threshold": [800.0]}, curves=True)
    d = table6.to_dict()
    d["joint"][0]["threshold"] = 800.0
    direct = stickslip.Study.from_dict(d, table6.path).run().to_pandas()
    pd.testing.assert_frame_equal(out.curves(0), direct, check_exact=True)


def test_grid_over_a_level_and_an_integer_key(table6):
    d = stickslip.design(table6, {"excitation.levels[0]": [100.0, 3000.0],
                                  "harmonic_balance.harmonics": (3, 7, 3)})
    assert d.keys == ["excitation.levels[0]", "harmonic_balance.harmonics"]
    np.testing.assert_array_equal(d.samples, [[100, 3], [100, 5], [100, 7], [3000, 3], [3000, 5], [3000, 7]])


@pytest.mark.parametrize("vary, message", [
    ({"joint.blade9.threshold": (1.0, 2.0)},
     '--vary joint.blade9.threshold: `joint` has no table named "blade9" (names: "joint")'),
    ({"joint.joint.law": (1.0, 2.0)}, '--vary joint.joint.law: holds a string "jenkins", not a number'),
    ({"excitation.levels[4]": (1.0, 2.0)}, "--vary excitation.levels[4]: index 4 is out of range"),
    ({"joint.joint.threshold": (-1.0, 2.0)},
     '--vary joint.joint.threshold: the value -1 is not accepted: [[joint]] "joint": threshold must be > 0 N, got -1'),
    ({"damping.alpah": (1.0, 2.0)}, "unknown field `alpah`"),
    ({"joint.joint.threshold": (2.0, 1.0)}, "LO must be below HI"),
])
def test_bad_keys_and_ranges_are_refused_before_running(table6, vary, message):
    with pytest.raises((stickslip.ParamError, stickslip.StudyError)) as e:
        stickslip.design(table6, vary, samples=4)
    assert message in str(e.value)


def test_a_cluster_address_that_does_not_answer_is_named_within_seconds(table6):
    started = time.perf_counter()
    # Port 9 (discard) on the loopback: nothing listens there.
    with pytest.raises(stickslip.ParamError, match="no Dask scheduler answers at tcp://127.0.0.1:9"):
        stickslip.run_parameters(table6, KEYS, samples=2, scheduler="dask", address="tcp://127.0.0.1:9",
                                 timeout=2.0)
    # Told within the timeout plus Dask's connection retries, not after minutes.
    assert time.perf_counter() - started < 15.0


def test_cli_shards_merged_equal_the_unsharded_run_and_the_python_table(root, cli, tmp_path, serial):
    study = tmp_path / "study.toml"
    text = (root / "examples" / "jenkins-1dof" / "study.toml").read_text()
    study.write_text(text.replace("levels = [100.0, 1000.0, 3000.0, 10000.0]", "levels = [1000.0]"))
    vary = ["--vary", "joint.joint.threshold=500:2000", "--vary", "damping.alpha=20:50"]
    common = [study, *vary, "--samples", "40", "--seed", "11", "--quiet"]
    cli("params", *common, "--out", tmp_path / "whole")
    for i in (1, 2, 3):
        cli("params", *common, "--shard", f"{i}/3", "--out", tmp_path / "sharded")
    cli("merge", tmp_path / "sharded")
    whole = (tmp_path / "whole" / "samples.csv").read_text()
    assert (tmp_path / "sharded" / "samples.csv").read_text() == whole
    # The same samples and summaries as the Python table (the same seed draws the same design).
    table = pd.read_csv(tmp_path / "whole" / "samples.csv", skiprows=1)
    numeric = ["sample", *KEYS, "level_N", "peak_frequency_Hz", "peak_amplitude_m", "peak_energy_J", "points"]
    np.testing.assert_allclose(table[numeric].to_numpy(float), serial[numeric].to_numpy(float), rtol=1e-12, atol=0)


def test_merge_refuses_a_missing_shard(root, cli, tmp_path):
    study = root / "examples" / "jenkins-1dof" / "study.toml"
    cli("params", study, "--vary", "joint.joint.threshold=800,900", "--shard", "1/2", "--quiet", "--out", tmp_path)
    p = cli("merge", tmp_path, check=False)
    assert p.returncode != 0
    assert "1 of 2 shard(s) missing: shard-2-of-2.csv" in p.stderr


CHAIN = """
[model]
dofs = ["a", "b", "c", "d", "e", "f"]
mass = [1.0, 1.2, 0.8, 1.1, 0.9, 1.3]
stiffness = [[ 2.0e6, -1.0e6,  0.0,    0.0,    0.0,    0.0],
             [-1.0e6,  2.0e6, -1.0e6,  0.0,    0.0,    0.0],
             [ 0.0,   -1.0e6,  2.0e6, -1.0e6,  0.0,    0.0],
             [ 0.0,    0.0,   -1.0e6,  2.0e6, -1.0e6,  0.0],
             [ 0.0,    0.0,    0.0,   -1.0e6,  2.0e6, -1.0e6],
             [ 0.0,    0.0,    0.0,    0.0,   -1.0e6,  2.0e6]]
[reduction]
method = "enriched"
retain = ["a", "c", "d"]
modes = 2
release_modes = 1
[damping]
alpha = 20.0
[[load]]
name = "shaker"
dof = "a"
[[joint]]
name = "j"
law = "jenkins"
between = ["c", "d"]
stiffness = 1.0e6
replaces_stiffness = true
threshold = 40.0
[excitation]
load = "shaker"
levels = [60.0]
[sweep]
start_hz = 60.0
end_hz = 180.0
[harmonic_balance]
harmonics = 3
samples = 64
[[output]]
name = "a"
dof = "a"
"""


def test_samples_on_a_kept_reduction_equal_samples_built_alone(tmp_path):
    # Threshold and Rayleigh damping leave the (enriched) reduction unchanged: the samples of
    # a batch, and the batches after it, run on the first sample's reduced model. Each curve
    # must be the one of the sample's own study run from scratch, to 1e-12 relative (the same
    # numbers in the same order: round-off at most).
    path = tmp_path / "chain.toml"
    path.write_text(CHAIN)
    study = stickslip.Study.from_toml(path)
    keys = {"joint.j.threshold": (20.0, 60.0), "damping.alpha": (5.0, 40.0)}
    out = stickslip.run_parameters(study, keys, samples=6, seed=2, curves=True, batch_size=3)
    assert not out.failed
    for o in out.outcomes:
        d = study.to_dict()
        d["joint"][0]["threshold"], d["damping"]["alpha"] = (float(x) for x in o["values"])
        alone = stickslip.Study.from_dict(d, study.path).run().to_pandas()
        kept = out.curves(o["sample"])
        assert len(alone) > 10 and list(kept.columns) == list(alone.columns)
        np.testing.assert_allclose(kept.to_numpy(dtype=float), alone.to_numpy(dtype=float), rtol=1e-12, atol=0)
