"""The timed stages of scripts/run-tests (scripts/env.sh, dyadfmu_stage and dyadfmu_job): each
stage's CPU seconds are its own processes', a failure inside a stage stops it there, a failed
background job fails the run with its log shown, a run that stops ends the jobs still running,
and the table at the end names every stage that ran and the one that failed."""

from __future__ import annotations

import subprocess
import sys
import textwrap
import time
from pathlib import Path

from dyadfmu import paths

# burn SECONDS: a child process that uses SECONDS of CPU, whatever else the machine is doing
BURN = "import sys, time\nwhile time.process_time() < float(sys.argv[1]):\n    pass\n"


def _run(tmp_path: Path, body: str) -> tuple[subprocess.CompletedProcess, dict[str, list[str]]]:
    """Runs BODY after dyadfmu_stages_init in a bash script; returns the run and the rows of its
    table (stage name: start, wall, CPU, result)."""
    script = tmp_path / "run-something"
    env_sh = paths.ROOT / "scripts" / "env.sh"
    (tmp_path / "burn").write_text(f"#!{sys.executable}\n{BURN}")
    (tmp_path / "burn").chmod(0o755)
    head = f'set -euo pipefail\nsource "{env_sh}"\ndyadfmu_stages_init "{tmp_path}/stages"\n'
    head += f'BURN="{tmp_path}/burn"\n'
    script.write_text(head + textwrap.dedent(body))
    done = subprocess.run(["/bin/bash", str(script)], capture_output=True, text=True, timeout=120)
    table = done.stdout.partition("CPU = user + system seconds\n")[2].splitlines()[1:]
    rows = {}
    for line in filter(lambda line: line.startswith("   "), table):
        name = line.split()[0]  # the whole run's row, total, has no start
        rows[name] = ["", *line.split(None, 3)[1:]] if name == "total" else line.split(None, 4)[1:]
    return done, rows


def test_a_stage_counts_its_own_processes_cpu_and_not_a_background_stages(tmp_path):
    done, rows = _run(
        tmp_path,
        """
        dyadfmu_job burner dyadfmu_stage burn $BURN 1.0
        dyadfmu_stage idle sleep 0.3
        dyadfmu_stage work $BURN 0.5
        dyadfmu_job_wait burner
        """,
    )
    assert done.returncode == 0, done.stderr
    assert [rows[name][3] for name in ("burn", "idle", "work", "total")] == ["ok"] * 4
    cpu = {name: float(row[2]) for name, row in rows.items()}
    assert 0.9 <= cpu["burn"] < 1.5 and 0.45 <= cpu["work"] < 0.9 and cpu["idle"] < 0.2
    assert cpu["total"] >= cpu["burn"] + cpu["work"]
    assert float(rows["idle"][1]) >= 0.3
    assert "job burner done" in done.stderr


def test_a_job_that_ended_during_a_stage_is_shown_once_and_waited_for_once(tmp_path):
    done, rows = _run(
        tmp_path,
        """
        dyadfmu_job quick dyadfmu_stage quick echo quick job output
        dyadfmu_stage slow sleep 0.5
        dyadfmu_job_wait quick
        dyadfmu_stage last true
        """,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.count("quick job output") == 1 and "job quick done" in done.stderr
    assert [rows[name][3] for name in ("quick", "slow", "last", "total")] == ["ok"] * 4


def test_a_failing_command_stops_its_stage_there(tmp_path):
    done, rows = _run(
        tmp_path,
        """
        steps() { echo first; false; echo second; }
        dyadfmu_stage steps steps
        dyadfmu_stage never true
        """,
    )
    assert done.returncode == 1
    assert "first\n" in done.stdout and "second\n" not in done.stdout
    assert rows["steps"][3] == "FAILED (exit 1)" and "never" not in rows
    assert rows["total"][3] == "FAILED: steps"


def test_a_failed_background_job_fails_the_run_with_its_log_shown(tmp_path):
    done, rows = _run(
        tmp_path,
        """
        lane() {
            dyadfmu_stage first echo the first stage of the lane
            dyadfmu_stage second sh -c 'echo what went wrong; exit 3'
            dyadfmu_stage third true
        }
        dyadfmu_job lane lane
        dyadfmu_stage meanwhile sleep 0.5
        dyadfmu_stage after true
        dyadfmu_job_wait lane
        """,
    )
    assert done.returncode == 3
    assert "job lane failed (exit 3); its log:" in done.stderr
    assert "what went wrong" in done.stderr and "the first stage of the lane" in done.stderr
    assert rows["first"][3] == "ok" and rows["second"][3] == "FAILED (exit 3)"
    assert "third" not in rows and "after" not in rows  # collected before the next stage
    assert rows["total"][3] == "FAILED: second"


def test_a_run_that_stops_ends_the_jobs_still_running_and_shows_a_failed_ones_log(tmp_path):
    pid_file = tmp_path / "sleeper.pid"
    done, rows = _run(
        tmp_path,
        f"""
        sleeper() {{ sleep 60 & echo $! > "{pid_file}"; wait; }}
        dyadfmu_job slow dyadfmu_stage sleeper sleeper
        dyadfmu_job failing dyadfmu_stage early sh -c 'echo why the job failed; exit 5'
        while [ ! -s "{pid_file}" ]; do sleep 0.05; done
        dyadfmu_stage broken sh -c 'sleep 0.5; exit 4'
        """,
    )
    assert done.returncode == 4
    assert "job failing failed too; its log:\n== stage early\nwhy the job failed\n" in done.stderr
    assert rows["sleeper"][3] == "stopped (the run ended)" and rows["early"][3] == "FAILED (exit 5)"
    assert rows["broken"][3] == "FAILED (exit 4)"
    assert float(rows["total"][1]) < 30
    assert not _alive(int(pid_file.read_text()))


def _alive(pid: int) -> bool:
    """Whether process PID still runs (a zombie, ended but not yet reaped, does not)."""
    for _ in range(20):
        try:
            state = Path(f"/proc/{pid}/stat").read_text().rpartition(") ")[2][0]
        except FileNotFoundError:
            return False
        if state == "Z":
            return False
        time.sleep(0.1)
    return True


def test_a_run_stopped_by_a_signal_says_so(tmp_path):
    """A run that receives SIGTERM ends when its stage does, its status 143 and its table's
    total FAILED, not ok."""
    done, rows = _run(
        tmp_path,
        """
        main=$$
        dyadfmu_stage first true
        dyadfmu_stage doomed sh -c "kill -TERM $main; sleep 0.3"
        dyadfmu_stage after true
        """,
    )
    assert done.returncode == 143
    assert rows["first"][3] == "ok" and "after" not in rows
    assert rows["total"][3] == "FAILED (exit 143)"
