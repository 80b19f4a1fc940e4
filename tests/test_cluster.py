"""Runs on a real Dask scheduler with two workers on loopback (issue 26), and the local
executor the default install uses: bench through --cluster, a portfolio race, a worker
killed mid-run, Ctrl-C, and clear errors where a cluster cannot be used."""
from __future__ import annotations

import csv
import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from dataclasses import replace
from pathlib import Path

import pytest

from fossil_dsl.cluster.executors import EVENTS, DaskExecutor, LocalExecutor
from fossil_dsl.cluster.jobs import Job, run_job
from fossil_dsl.frontends.arguments import OptionError
from fossil_dsl.frontends.checking import load
from fossil_dsl.frontends.cli import main
from fossil_dsl.frontends.portfolio import race

pytest.importorskip("distributed")  # the [cluster] extra, which '.[test]' installs

SPECS = Path(__file__).resolve().parent.parent / "specs"
# two rows of the benchmark portfolio that take a second each
QUICK = [SPECS / "benchmarks" / "row01_stability_nonpoly2.fsl",
         SPECS / "benchmarks" / "row16_safety_dt_two_room.fsl"]
# a false property: its runs learn until their deadline (a job that lasts; not one of an
# unstable origin, which is refuted at once)
LASTING = SPECS / "false" / "f129_softening_duffing_past_separatrix_safety.fsl"


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _start(*arguments: str) -> subprocess.Popen:
    # its own process group: killing it kills the runs it started too (a machine lost)
    return subprocess.Popen([sys.executable, "-m", *arguments], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)


def _kill(process: subprocess.Popen) -> None:
    try:
        os.killpg(process.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    process.wait(timeout=30)


class Loopback:
    def __init__(self):
        self.address = f"tcp://127.0.0.1:{_free_port()}"
        self.scheduler = _start("distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                                "--port", self.address.rsplit(":", 1)[1], "--no-dashboard")
        self.workers = [_start("distributed.cli.dask_worker", self.address, "--nthreads", "1",
                               "--no-nanny", "--no-dashboard", "--name", f"w{i}")
                        for i in range(2)]

    def executor(self) -> DaskExecutor:
        executor = DaskExecutor(self.address)
        executor.client.wait_for_workers(2, timeout=60)
        return executor

    def close(self) -> None:
        for process in self.workers + [self.scheduler]:
            _kill(process)


@pytest.fixture(scope="module")
def loopback():
    cluster = Loopback()
    try:
        yield cluster
    finally:
        cluster.close()


def _job(path: Path, seed: int = 0, timeout: float = 60.0, **extra) -> Job:
    return Job(path.read_text(), path.stem, seed, timeout, label=f"{path.stem} {seed}", **extra)


def test_bench_runs_on_the_cluster_and_writes_runs_csv(loopback, tmp_path, capsys):
    loopback.executor().close()  # both workers are up
    code = main(["bench", *map(str, QUICK), "--seeds", "2", "--timeout", "60",
                 "--out", str(tmp_path), "--cluster", loopback.address])
    assert code == 0
    with (tmp_path / "runs.csv").open() as handle:
        runs = list(csv.DictReader(handle))
    assert len(runs) == 4
    assert {(r["spec"], r["seed"]) for r in runs} == {
        (p.stem, s) for p in QUICK for s in ("0", "1")}
    assert all(r["outcome"] == "certified" for r in runs), runs
    assert all(r["worker"].startswith("tcp://127.0.0.1:") for r in runs)
    assert "Dask scheduler" in (tmp_path / "table.md").read_text()


def test_a_worker_killed_mid_run_loses_and_duplicates_nothing(loopback):
    executor = loopback.executor()
    try:
        jobs = [_job(QUICK[i % 2], seed=i) for i in range(4)]
        victim = threading.Thread(target=_kill_first_busy_worker, args=(loopback, executor),
                                  daemon=True)
        victim.start()
        done = []
        outputs = executor.run(jobs, lambda i, output: done.append(i))
        victim.join(timeout=60)
    finally:
        executor.close()
    assert sorted(done) == [0, 1, 2, 3]  # each job reported exactly once
    verdicts = [json.loads(o.stdout)["verdict"] for o in outputs]
    assert verdicts == ["certified"] * 4
    assert [json.loads(o.stdout)["seed"] for o in outputs] == [0, 1, 2, 3]
    assert any(o.attempts == 2 for o in outputs), [o.attempts for o in outputs]
    assert len({o.worker for o in outputs}) == 1  # all finished on the survivor
    loopback.workers = [w for w in loopback.workers if w.poll() is None]
    loopback.workers.append(_start("distributed.cli.dask_worker", loopback.address,
                                   "--nthreads", "1", "--no-nanny", "--no-dashboard"))


def _kill_first_busy_worker(loopback: Loopback, executor: DaskExecutor) -> None:
    """Once a job has started on a worker, and a second later, kill that worker."""
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        events = executor.client.get_events(EVENTS)
        if events:
            address = events[-1][1]["worker"]
            time.sleep(1.0)
            pids = executor.client.run(os.getpid, workers=[address])
            for process in loopback.workers:
                if process.pid == pids[address]:
                    _kill(process)
                    return
        time.sleep(0.1)


def test_portfolio_on_the_cluster_is_judged_here_and_names_its_winner(loopback, tmp_path,
                                                                      capsys):
    code = main([str(QUICK[0]), "--portfolio", "2", "--cluster", loopback.address,
                 "--seed", "3", "-o", str(tmp_path), "--json"])
    data = json.loads(capsys.readouterr().out)
    assert code == 0 and data["verdict"] == "certified"
    record = data["portfolio"]
    assert [s["seed"] for s in record["strategies"]] == [3, 4]
    assert record["winner"] in ("seed 3", "seed 4")
    assert record["repeat"] == f"--seed {data['seed']}"
    assert data["kernel"]["verdict"] == "certified"
    assert json.loads((tmp_path / "result.json").read_text())["portfolio"] == record


class Forging:
    """An executor whose worker claims "certified" for a false V (a forged result.json)."""
    description = "a forging worker"

    def run(self, jobs, on_done=lambda i, o: None, wins=lambda o: False):
        outputs = []
        for index, job in enumerate(jobs):
            output = run_job(job)
            data = json.loads(output.files["result.json"])
            data["functions"] = {name: "x0^2 - x1^2" for name in data["functions"]}
            files = dict(output.files, **{"result.json": json.dumps(data).encode()})
            outputs.append(replace(output, files=files))
            on_done(index, outputs[-1])
        return outputs

    def close(self):
        pass


def test_a_workers_certified_is_not_taken_on_trust():
    """The winner's formulas are judged again by this machine's kernel."""
    spec = load(QUICK[0])
    result = race(spec, 1, Forging(), timeout=60)
    assert not result.certified
    assert str(result.formulas["V"]) == "x0^2 - x1^2"
    assert any(not p.proved for p in result.kernel.proofs)
    assert "kernel does not prove" in result.reason
    assert result.portfolio["winner"] is None


def test_the_first_certified_strategy_stops_the_others():
    lasting = _job(LASTING, timeout=120)
    quick = _job(QUICK[0])
    started = time.monotonic()
    outputs = LocalExecutor(2).run([lasting, quick], wins=lambda o: o.returncode == 0)
    assert time.monotonic() - started < 60
    assert outputs[0].stopped and outputs[0].returncode is None
    assert json.loads(outputs[1].stdout)["verdict"] == "certified"


@pytest.mark.parametrize("where", ["local", "dask"])
def test_ctrl_c_stops_every_job(loopback, where):
    executor = LocalExecutor(2) if where == "local" else loopback.executor()
    jobs = [_job(QUICK[0]), _job(LASTING, timeout=120), _job(LASTING, seed=1, timeout=120)]

    def interrupt(index, output):
        raise KeyboardInterrupt

    started = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            executor.run(jobs, interrupt)
    finally:
        if where == "dask":
            _wait_idle(executor)
            executor.close()
    assert time.monotonic() - started < 60  # not the lasting jobs' 120 s


def _wait_idle(executor: DaskExecutor) -> None:
    """Until no worker runs a task (the stopped jobs have ended)."""
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        if not any(executor.client.processing().values()):
            return
        time.sleep(0.2)
    raise AssertionError("jobs still running 30 s after Ctrl-C")


def test_an_unreachable_scheduler_is_a_clear_error(tmp_path, capsys, monkeypatch):
    from fossil_dsl.cluster import executors
    monkeypatch.setattr(executors, "CONNECT_SECONDS", 2.0)  # Dask retries until then
    address = f"tcp://127.0.0.1:{_free_port()}"
    code = main(["bench", str(QUICK[0]), "--seeds", "1", "--out", str(tmp_path),
                 "--cluster", address])
    assert code == 2
    assert f"cannot reach the Dask scheduler at {address}" in capsys.readouterr().err


def test_a_malformed_address_is_refused_before_running(capsys):
    with pytest.raises(SystemExit) as stop:
        main([str(QUICK[0]), "--cluster", "not an address"])
    assert stop.value.code == 2
    assert "tcp://HOST:PORT" in capsys.readouterr().err


def test_race_refuses_options_its_runs_cannot_carry():
    with pytest.raises(OptionError, match="learning_rate"):
        race(load(QUICK[0]), 2, learning_rate=0.1)


def test_portfolio_refuses_learn_only(capsys):
    assert main([str(QUICK[0]), "--portfolio", "2", "--learn-only"]) == 2
    assert "--learn-only proves nothing" in capsys.readouterr().err


def test_without_dask_cluster_says_what_to_install_and_local_runs_work(tmp_path):
    """The default install has no Dask: nothing local needs it, --cluster says so."""
    script = ("import sys; sys.modules['distributed'] = None; sys.modules['dask'] = None\n"
              "from fossil_dsl.frontends.cli import main\n"
              f"local = main(['bench', {str(QUICK[0])!r}, '--seeds', '1', "
              f"'--out', {str(tmp_path)!r}])\n"
              f"remote = main([{str(QUICK[0])!r}, '--cluster', 'tcp://127.0.0.1:1'])\n"
              "print('codes', local, remote)\n")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=300)
    assert "codes 0 2" in done.stdout, done.stderr
    assert "pip install 'fossil_dsl[cluster]'" in done.stderr


def test_split_verification_on_the_cluster(loopback, tmp_path, capsys):
    """`--split --cluster`: the interval queries' pieces are checked by the workers."""
    spec = SPECS / "literature" / "lit01_damped_pendulum.fsl"
    code = main([str(spec), "--split", "1", "--cluster", loopback.address, "--json"])
    data = json.loads(capsys.readouterr().out)
    assert code == 0 and data["verdict"] == "certified"
    procedures = [o["procedure"] for o in data["kernel"]["obligations"]]
    assert any(p.startswith("interval, split into") for p in procedures), procedures
