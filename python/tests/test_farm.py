"""The Ray runner (``python -m dvr.farm``) on a real local Ray cluster: one head and two
worker nodes, separate ``ray start`` processes each declaring one GPU, inside a network
namespace with only loopback (``unshare -n``), so nothing leaves the machine."""

import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile

import pytest

# Shards of about a second each, so the two nodes work at once.
SCENE = ["--scene", "cloud/orbit", "--frames", "8", "--size", "32x32", "--volume-size", "16", "--ref-spp", "1024"]
EVAL = [
    "--scene", "cloud/orbit,phantom/tf-sweep,cloud/point-light", "--frames", "4", "--size", "16x12",
    "--volume-size", "16", "--ref-spp", "8", "--denoiser", "none,ours",
]  # fmt: skip


def files(folder: pathlib.Path) -> dict:
    """Every file under ``folder`` by relative path, with its bytes."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def scores(csv: pathlib.Path, times: int) -> list:
    """A CSV's lines without their last ``times`` columns (measured GPU times)."""
    return [",".join(line.split(",")[:-times]) for line in csv.read_text().splitlines()]


def in_loopback_namespace() -> list:
    """The command prefix of a new network namespace: as root a plain one, else inside a
    user namespace that maps us to root."""
    unshare = shutil.which("unshare")
    if unshare is None:
        pytest.fail("unshare (util-linux) is needed to keep the Ray cluster on loopback")
    return [unshare, "-n"] if os.geteuid() == 0 else [unshare, "-rn"]


@pytest.fixture(scope="module")
def farm_runs(dvr_bin, tmp_path_factory):
    """Runs, on one cluster, a 4-shard reference job (shard 1's worker killed once) and a
    3-shard eval; returns the folders and summaries."""
    tmp = tmp_path_factory.mktemp("farm")
    ray_cli = pathlib.Path(sys.executable).parent / "ray"
    assert ray_cli.is_file(), f"ray is not installed beside {sys.executable}"
    ray_tmp = tempfile.mkdtemp(prefix="dvr-ray-", dir="/tmp")  # short: it holds sockets
    marker = tmp / "shard1-killed"
    port = 6391
    start = f"{ray_cli} start --node-ip-address=127.0.0.1 --num-cpus=1 --object-store-memory=100000000 --disable-usage-stats"
    farm = f"{sys.executable} -m dvr.farm"
    q = lambda args: " ".join(args)  # noqa: E731 (no argument here needs quoting)
    script = f"""
set -eu
ip link set lo up
# The cluster's auth token in a home of its own: the user's ~/.ray stays untouched.
export RAY_USAGE_STATS_ENABLED=0 RAY_ADDRESS=127.0.0.1:{port} RAY_AUTH_MODE=token HOME={tmp}/home
trap '{ray_cli} stop --force >/dev/null 2>&1 || true' EXIT
{ray_cli} get-auth-token --generate >/dev/null
{start} --head --port={port} --num-gpus=0 --include-dashboard=false --temp-dir={ray_tmp}
{start} --address=127.0.0.1:{port} --num-gpus=1
{start} --address=127.0.0.1:{port} --num-gpus=1
# What a writer killed mid-write on another machine left in the cache an hour ago.
mkdir -p {tmp}/farm-ref/reference
printf 'half a frame' > {tmp}/farm-ref/reference/.0003.exr.elsewhere.4242.0.tmp
touch -d '1 hour ago' {tmp}/farm-ref/reference/.0003.exr.elsewhere.4242.0.tmp
DVR_FARM_KILL_ONCE=1:{marker} {farm} reference --shards 4 --dvr {dvr_bin} --summary {tmp}/ref.json -- {q(SCENE)} --out {tmp}/farm-ref
{farm} eval --shards 3 --dvr {dvr_bin} --summary {tmp}/eval.json -- {q(EVAL)} --out {tmp}/farm-eval
# The driver killed mid-run (its shards and their dvr processes with it, some perhaps
# mid-write), then the same job again: it finishes what is missing and no more.
{farm} reference --shards 4 --dvr {dvr_bin} --summary {tmp}/killed.json -- {q(SCENE)} --out {tmp}/farm-killed &
driver=$!
until [ "$(ls {tmp}/farm-killed/reference/*.exr 2>/dev/null | wc -l)" -ge 2 ]; do sleep 0.1; done
kill -9 $driver
wait $driver || true
# Anchored at dvr's path: this script's own command line names the folder too.
pkill -9 -f -- '^{dvr_bin} .*--out {tmp}/farm-killed' || true
sleep 1
ls -a {tmp}/farm-killed/reference > {tmp}/killed-left.txt
{farm} reference --shards 4 --dvr {dvr_bin} --summary {tmp}/rerun.json -- {q(SCENE)} --out {tmp}/farm-killed
"""
    run = subprocess.run(
        in_loopback_namespace() + ["bash", "-c", script], capture_output=True, text=True, timeout=600
    )
    shutil.rmtree(ray_tmp, ignore_errors=True)
    assert run.returncode == 0, f"the farm failed (exit {run.returncode}):\n{run.stdout[-3000:]}\n{run.stderr[-6000:]}"
    single = [dvr_bin, "reference", *SCENE, "--out", str(tmp / "one-ref")]
    subprocess.run(single, check=True, capture_output=True)
    return tmp, marker, run.stderr


@pytest.fixture(scope="module")
def one_eval(dvr_bin, tmp_path_factory):
    """The eval of EVAL as one dvr run."""
    out = tmp_path_factory.mktemp("one") / "eval"
    subprocess.run([dvr_bin, "eval", *EVAL, "--out", str(out)], check=True, capture_output=True)
    return out


def assert_same_eval(farmed: pathlib.Path, one: pathlib.Path, methods=("none", "ours")) -> None:
    """The scores and frames of one run: every reference and output frame byte for byte,
    every CSV but its GPU times."""
    for csv, times in (("metrics.csv", 1), ("summary.csv", 2), ("baseline.csv", 2)):
        assert scores(farmed / csv, times) == scores(one / csv, times), csv
    for scene in ("cloud_orbit", "phantom_tf-sweep", "cloud_point-light"):
        for folder in ("reference", *methods):
            assert files(farmed / scene / folder) == files(one / scene / folder), f"{scene}/{folder}"


def test_reference_shards_run_on_two_nodes_each_frame_once_and_equal_one_run(farm_runs):
    tmp, marker, log = farm_runs
    summary = json.loads((tmp / "ref.json").read_text())
    shards = summary["references"]
    assert [s["index"] for s in shards] == [0, 1, 2, 3]
    nodes = {s["node"] for s in shards}
    assert len(nodes) == 2, f"the shards ran on {len(nodes)} node(s): {nodes}\n{log[-1500:]}"
    selected = sorted(f for s in shards for r in s["report"]["references"] for f in r["selected"])
    assert selected == list(range(8)), "every frame in exactly one shard"
    for s in shards:
        (r,) = s["report"]["references"]
        assert sorted(r["rendered"] + r["reused"]) == r["selected"]
    one, farmed = files(tmp / "one-ref" / "reference"), files(tmp / "farm-ref" / "reference")
    assert len(one) == 8 * 2 + 2, sorted(one)  # EXR + PNG a frame, the key, the lock
    assert farmed == one, "the farm's references differ from one run's"
    assert "4/4 shards" in log


def test_a_killed_driver_is_rerun_without_redoing_finished_frames(farm_runs):
    tmp, _, _ = farm_runs
    left = (tmp / "killed-left.txt").read_text().split()
    finished = sorted(n for n in left if n.endswith(".exr") and not n.startswith("."))
    assert len(finished) >= 2, left
    shards = json.loads((tmp / "rerun.json").read_text())["references"]
    rendered = sorted(f for s in shards for r in s["report"]["references"] for f in r["rendered"])
    reused = sorted(f for s in shards for r in s["report"]["references"] for f in r["reused"])
    assert sorted(rendered + reused) == list(range(8))
    assert [f"{f:04d}.exr" for f in reused] == finished, (finished, reused)
    # Whatever the killed writers left is gone, and the frames are one run's.
    assert files(tmp / "farm-killed" / "reference") == files(tmp / "one-ref" / "reference")


def test_a_temporary_a_killed_writer_left_is_removed_not_read(farm_runs):
    tmp, _, _ = farm_runs
    left = [p.name for p in (tmp / "farm-ref" / "reference").iterdir() if p.name.endswith(".tmp")]
    assert not left, left


def test_a_shard_whose_worker_was_killed_is_retried(farm_runs):
    tmp, marker, _ = farm_runs
    assert marker.exists(), "shard 1's first attempt ran and killed its worker"
    shards = json.loads((tmp / "ref.json").read_text())["references"]
    assert [s["retry"] for s in shards] == [False, True, False, False]


def test_a_farmed_eval_merges_into_the_scores_of_one_run(farm_runs, one_eval):
    tmp, _, _ = farm_runs
    summary = json.loads((tmp / "eval.json").read_text())
    units = sorted(
        (r["scene"], f) for s in summary["references"] for r in s["report"]["references"] for f in r["selected"]
    )
    assert len(units) == 12 and len(set(units)) == 12, "every (scene, frame) reference once"
    scenes = sorted(n for s in summary["scenes"] for n in s["report"]["scenes"])
    assert scenes == sorted(["cloud/orbit", "phantom/tf-sweep", "cloud/point-light"])
    assert_same_eval(tmp / "farm-eval", one_eval)


def test_a_cluster_without_gpus_is_refused_not_waited_on(dvr_bin, tmp_path):
    """Without RAY_ADDRESS the runner starts a local Ray with this machine's GPUs (none
    here): a shard that needs one could never run, so it says so at once."""
    env = {k: v for k, v in os.environ.items() if k != "RAY_ADDRESS"}
    env.update(RAY_USAGE_STATS_ENABLED="0", RAY_AUTH_MODE="token", HOME=str(tmp_path / "home"))
    cmd = [sys.executable, "-m", "dvr.farm", "reference", "--shards", "2", "--dvr", dvr_bin, "--", *SCENE]
    cmd += ["--out", str(tmp_path / "x")]
    run = subprocess.run(
        in_loopback_namespace() + ["bash", "-c", 'ip link set lo up && exec "$@"', "-", *cmd],
        capture_output=True, text=True, timeout=300, env=env,
    )  # fmt: skip
    assert run.returncode == 1, run.stderr[-3000:]
    assert "declares 0 GPU(s), a shard needs 1" in run.stderr
    assert not (tmp_path / "x").exists()


def test_the_slurm_array_script_maps_task_ids_onto_shards(dvr_bin, one_eval, root, tmp_path):
    """tools/farm/dvr.sbatch as each array task runs it (the environment Slurm sets), an
    array starting at 3 and one at 0, then the merge."""
    out = str(tmp_path / "eval")
    script = str(root / "tools/farm/dvr.sbatch")
    for stage, ids in (("references", range(3, 7)), ("scenes", range(0, 2))):
        for task in ids:
            env = dict(os.environ, DVR=dvr_bin, SLURM_ARRAY_TASK_ID=str(task))
            env.update(SLURM_ARRAY_TASK_MIN=str(ids.start), SLURM_ARRAY_TASK_COUNT=str(len(ids)))
            run = subprocess.run(["bash", script, stage, *EVAL, "--out", out], env=env, capture_output=True, text=True)
            assert run.returncode == 0, run.stderr
            assert f"shard {task - ids.start}/{len(ids)}" in run.stdout, run.stdout
    subprocess.run([dvr_bin, "eval", *EVAL, "--out", out, "--merge"], check=True, capture_output=True)
    assert_same_eval(tmp_path / "eval", one_eval)
    bad = subprocess.run(["bash", script, "everything"], env=dict(os.environ, SLURM_ARRAY_TASK_ID="0", SLURM_ARRAY_TASK_COUNT="1"), capture_output=True, text=True)
    assert bad.returncode == 2 and "references or scenes" in bad.stderr


def test_the_kubernetes_indexed_job_renders_each_reference_once(dvr_bin, one_eval, root, tmp_path):
    """The indexed Job's pod command, run once per completion index with the index in
    JOB_COMPLETION_INDEX as Kubernetes sets it, a small eval in place of the suite and a
    folder in place of the volume."""
    import yaml

    job = yaml.safe_load((root / "tools/farm/k8s-references-job.yaml").read_text())
    spec = job["spec"]
    assert spec["completionMode"] == "Indexed"
    n = spec["completions"]
    pod = spec["template"]["spec"]
    (container,) = pod["containers"]
    assert container["resources"]["limits"]["nvidia.com/gpu"] == 1
    assert container["volumeMounts"][0]["mountPath"] == "/data"
    command = container["command"]
    suite = "--scene suite --size 256x256 --ref-spp 1024 --out /data/eval"
    assert command[:2] == ["sh", "-c"] and suite in command[2], command
    assert f'--shard "$JOB_COMPLETION_INDEX/{n}"' in command[2], "completions and --shard agree"
    small = command[2].replace(suite, " ".join(EVAL) + f" --out {tmp_path}/eval")
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    (bin_dir / "dvr").symlink_to(dvr_bin)
    for index in range(n):
        env = dict(os.environ, JOB_COMPLETION_INDEX=str(index), PATH=f"{bin_dir}:{os.environ['PATH']}")
        subprocess.run(["sh", "-c", small], env=env, check=True, capture_output=True)
    verify = [dvr_bin, "eval", *EVAL, "--out", str(tmp_path / "eval"), "--references-only", "--verify"]
    subprocess.run(verify, check=True, capture_output=True)
    for scene in ("cloud_orbit", "phantom_tf-sweep", "cloud_point-light"):
        assert files(tmp_path / "eval" / scene / "reference") == files(one_eval / scene / "reference")
