"""Render references and evals across many GPUs with Ray: ``python -m dvr.farm``.

Each shard is one ``dvr`` process (``--shard I/N``) run as a Ray task that needs one GPU,
so every GPU renders on its own and a crashed driver or GPU takes one shard with it. The
processes write into one folder that every node sees (a shared file system); what they
write is what one ``dvr`` run writes, so a shard that dies is simply run again (Ray
retries tasks whose worker died) and finds the frames it already wrote. At the end the
driver checks the folder (``--verify``) or writes the eval's reports (``--merge``)::

    ray start --head                       # on one node; others: ray start --address=...
    export RAY_ADDRESS=<head>:6379
    python -m dvr.farm reference --shards 16 -- --scene mri/orbit --size 1280x720 --out refs
    python -m dvr.farm eval --shards 16 -- --scene suite --size 256x256 --out out/eval

``eval`` runs in two rounds: the references (a unit per frame of each scene), then the
methods (a unit per scene: temporal denoisers run a scene's frames in order), then the
merge; with ``--references-only`` among dvr's options, the references alone and the
check. Everything after ``--`` is passed to ``dvr`` as it is.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from typing import Any, Dict, List, Optional

#: Environment a shard needs from the driver: dvr's own variables (assets, device,
#: validation, parameter overrides) and the test hook below.
_PASSED_PREFIXES = ("DVR_",)

#: Test hook: ``"I:PATH"`` makes shard I, on its first attempt (while PATH does not
#: exist), kill its own Ray worker after starting dvr, as a crashed node would; Ray then
#: runs the shard again. Used by python/tests/test_farm.py.
KILL_ONCE = "DVR_FARM_KILL_ONCE"


class FarmError(RuntimeError):
    """A shard failed after its retries, or the folder is incomplete."""


def find_dvr(explicit: Optional[str]) -> str:
    """The dvr binary every node runs: ``--dvr``, ``DVR_BIN`` or ``dvr`` on PATH, as an
    absolute path (the nodes must see it at the same path)."""
    for candidate in (explicit, os.environ.get("DVR_BIN"), shutil.which("dvr")):
        if candidate and os.path.isfile(candidate):
            return os.path.abspath(candidate)
    raise FarmError("no dvr binary: pass --dvr PATH, set DVR_BIN, or put dvr on PATH")


def _shard(argv: List[str], env: Dict[str, str], cwd: str, index: int) -> Dict[str, Any]:
    """One shard in a Ray worker: runs dvr and returns its report, the node it ran on
    and whether it is a retry."""
    import ray

    node = ray.get_runtime_context().get_node_id()
    full_env = dict(os.environ)
    full_env.update(env)
    kill = env.get(KILL_ONCE, "")
    attempt_marker = kill.split(":", 1)[1] if kill.startswith(f"{index}:") else None
    retry = attempt_marker is not None and os.path.exists(attempt_marker)
    with tempfile.TemporaryDirectory() as tmp:
        report = os.path.join(tmp, "report.json")
        cmd = argv + ["--report", report]
        proc = subprocess.Popen(
            cmd, cwd=cwd, env=full_env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
        )
        if attempt_marker is not None and not retry:
            open(attempt_marker, "w").close()
            time.sleep(1.0)  # let it render part of its share
            proc.kill()
            proc.wait()
            os.kill(os.getpid(), signal.SIGKILL)
        out, err = proc.communicate()
        if proc.returncode != 0:
            tail = "\n".join(err.strip().splitlines()[-5:])
            raise FarmError(f"{' '.join(cmd)} exited {proc.returncode} on node {node}:\n{tail}")
        with open(report) as f:
            done = json.load(f)
    return {"index": index, "node": node, "retry": retry, "report": done, "stdout": out.strip()}


def _progress(done: int, total: int, what: str) -> None:
    width = 30
    filled = width * done // max(total, 1)
    line = f"farm: {what} [{'#' * filled}{'.' * (width - filled)}] {done}/{total} shards"
    end = "\n" if done == total or not sys.stderr.isatty() else "\r"
    print(line, end=end, file=sys.stderr, flush=True)


def run_shards(
    dvr: str,
    args: List[str],
    shards: int,
    what: str,
    gpus: float = 1.0,
    retries: int = 3,
) -> List[Dict[str, Any]]:
    """Runs ``dvr ARGS --shard I/SHARDS`` for every I as Ray tasks needing ``gpus`` GPUs
    each, retried up to ``retries`` times when their worker dies; returns each shard's
    result in shard order. Raises :class:`FarmError` when one fails for good."""
    import ray

    env = {k: v for k, v in os.environ.items() if k.startswith(_PASSED_PREFIXES)}
    # SPREAD: shards go to different nodes first, rather than queue on the first one
    # with a free GPU (each shard is seconds to hours of one GPU's work).
    task = ray.remote(_shard).options(
        num_gpus=gpus, max_retries=retries, retry_exceptions=False, scheduling_strategy="SPREAD"
    )
    pending = {
        task.remote([dvr] + args + ["--shard", f"{i}/{shards}"], env, os.getcwd(), i): i
        for i in range(shards)
    }
    results: Dict[int, Dict[str, Any]] = {}
    _progress(0, shards, what)
    failures = []
    while pending:
        ready, _ = ray.wait(list(pending), num_returns=1)
        i = pending.pop(ready[0])
        try:
            results[i] = ray.get(ready[0])
        except Exception as e:  # a RayTaskError wrapping FarmError, or a lost worker
            failures.append(f"shard {i}/{shards}: {e}")
        _progress(len(results) + len(failures), shards, what)
    if failures:
        raise FarmError("\n".join(failures))
    return [results[i] for i in range(shards)]


def _dvr_local(dvr: str, args: List[str]) -> None:
    """Runs dvr on the driver (the merge or the check), its output shown as it comes."""
    rc = subprocess.call([dvr] + args)
    if rc != 0:
        raise FarmError(f"{' '.join([dvr] + args)} exited {rc}")


def _connect(gpus: float) -> None:
    import ray

    if not ray.is_initialized():
        # RAY_ADDRESS names the cluster, as for every Ray program; without it Ray starts
        # a local one on this machine.
        ray.init(log_to_driver=False, configure_logging=False)
    have = ray.cluster_resources().get("GPU", 0)
    nodes = [n for n in ray.nodes() if n.get("Alive")]
    print(f"farm: a Ray cluster of {len(nodes)} node(s) with {have:g} GPU(s)", file=sys.stderr)
    if gpus > 0 and have < gpus:
        raise FarmError(
            f"the Ray cluster declares {have:g} GPU(s), a shard needs {gpus:g}: start its "
            "workers with `ray start --num-gpus N`, or pass --gpus-per-shard 0 to run on CPUs"
        )


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m dvr.farm",
        description="Shard dvr reference or dvr eval over a Ray cluster (RAY_ADDRESS).",
        usage="python -m dvr.farm {reference,eval} --shards N [options] -- DVR_OPTIONS",
        epilog="Options after -- go to dvr as they are.",
    )
    parser.add_argument("command", choices=["reference", "eval"])
    parser.add_argument("--shards", type=int, required=True, help="number of shards (tasks)")
    parser.add_argument("--gpus-per-shard", type=float, default=1.0, help="GPUs a shard needs (default 1)")
    parser.add_argument("--retries", type=int, default=3, help="retries of a shard whose worker died")
    parser.add_argument("--dvr", help="the dvr binary (default: DVR_BIN, else dvr on PATH)")
    parser.add_argument("--summary", help="write each shard's node, retry and report as JSON")
    argv = sys.argv[1:] if argv is None else argv
    cut = argv.index("--") if "--" in argv else len(argv)
    a = parser.parse_args(argv[:cut])
    rest = argv[cut + 1 :]
    if a.shards < 1:
        parser.error("--shards must be at least 1")
    try:
        dvr = find_dvr(a.dvr)
        _connect(a.gpus_per_shard)
        started = time.monotonic()
        summary: Dict[str, Any] = {"command": a.command, "shards": a.shards}
        if a.command == "reference":
            base = ["reference"] + rest
            summary["references"] = run_shards(dvr, base, a.shards, "references", a.gpus_per_shard, a.retries)
            _dvr_local(dvr, base + ["--verify"])
        elif "--references-only" in rest:
            base = ["eval"] + rest
            summary["references"] = run_shards(dvr, base, a.shards, "references", a.gpus_per_shard, a.retries)
            _dvr_local(dvr, base + ["--verify"])
        else:
            base = ["eval"] + rest
            refs = base + ["--references-only"]
            summary["references"] = run_shards(dvr, refs, a.shards, "references", a.gpus_per_shard, a.retries)
            summary["scenes"] = run_shards(dvr, base, a.shards, "scenes", a.gpus_per_shard, a.retries)
            _dvr_local(dvr, base + ["--merge"])
        summary["seconds"] = time.monotonic() - started
        nodes = {s["node"] for k in ("references", "scenes") for s in summary.get(k, [])}
        print(f"farm: {a.command} done in {summary['seconds']:.1f} s on {len(nodes)} node(s)", file=sys.stderr)
        if a.summary:
            with open(a.summary, "w") as f:
                json.dump(summary, f, indent=1)
    except FarmError as e:
        print(f"farm: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
