"""Bad arguments stop early and by name: the dyadfmu command's options (before any
co-simulation), the scripts/run-* wrappers (before they build), scripts/run-fuzz and the
fuzz driver (before they fuzz)."""

from __future__ import annotations

import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from dyadfmu import cli, paths
from dyadfmu.cosim import harness

SCRIPTS = paths.ROOT / "scripts"


@pytest.fixture
def no_work(monkeypatch):
    """A co-simulation started by mistake fails the test instead of running."""

    def refuse(*args, **kwargs):
        raise AssertionError("the co-simulation started despite a bad argument")

    monkeypatch.setattr(harness, "run_mechanism", refuse)


def _refused(argv: list[str], capsys) -> str:
    """dyadfmu's message for `argv`, which it must refuse with status 2."""
    with pytest.raises(SystemExit) as done:
        cli.main(argv)
    assert done.value.code == 2
    return capsys.readouterr().err


@pytest.mark.parametrize(
    "argv,said",
    [
        (["--revolutions", "0.01", "--steps", "8"], "--revolutions 0.01 at --steps 8 makes 0"),
        (["--revolutions", "1e300"], "argument --revolutions: must be a number above 0"),
        (["--revolutions", "nan"], "argument --revolutions: must be a number above 0"),
        (["--revolutions", "-1"], "argument --revolutions: must be a number above 0"),
        (["--steps", "1e3"], "argument --steps: not a whole number: '1e3'"),
        (["--steps", "3"], "argument --steps: must be from 4 to 100000, got 3"),
        (["--angle", "nan"], "argument --angle: must be a number from -36000 to 36000, got nan"),
        (["--angle", "inf"], "argument --angle: must be a number from -36000 to 36000, got inf"),
        (["four-bra"], "unknown mechanism four-bra"),
    ],
)
def test_run_refuses_a_bad_option_before_simulating(argv, said, capsys, no_work):
    assert said in _refused(["run", *argv], capsys)


# ---- path arguments: every command, every path option, one line before any work --------

#: Every path argument of every command: (the command's words, the option ("" for the
#: positional), its kind, the other arguments it needs).
PATH_ARGUMENTS = [
    ("run", "--out", "out"),
    ("run", "--build", "folder"),
    ("scene", "--out", "out"),
    ("scene", "--build", "folder"),
    ("study", "--out", "out"),
    ("study", "--build", "folder"),
    ("speed", "--build", "folder"),
    ("sweep", "STUDY.toml", "file"),
    ("sweep", "--out", "out"),
    ("sweep", "--build", "folder"),
    ("scenes", "--out", "out"),
    ("scenes", "--build", "folder"),
    ("cosim", "--out", "out"),
    ("plants", "--out", "out"),
    ("plants", "--build", "folder"),
    ("scene-bench", "--generator", "file"),
]


@pytest.fixture
def nothing_runs(monkeypatch):
    """The work of every command fails the test: a bad path must stop it before."""
    from dyadfmu.report import cosim as cosim_report
    from dyadfmu.report import plants as plants_report
    from dyadfmu.report import scenes as scenes_report
    from dyadfmu.study import long_chain

    def refuse(*args, **kwargs):
        raise AssertionError("the command started its work despite a bad path")

    for name in ("_run", "_scene", "_study", "_speed", "_sweep"):
        monkeypatch.setattr(cli, name, refuse)
    monkeypatch.setattr(scenes_report, "_runs", refuse)
    monkeypatch.setattr(cosim_report, "run_study", refuse)
    monkeypatch.setattr(plants_report, "measure", refuse)
    monkeypatch.setattr(long_chain, "measure", refuse)


def _bad_paths(tmp_path: Path, kind: str) -> list[tuple[str, str]]:
    """(path, what the message says) for a path argument of `kind` that cannot be used:
    in /proc (where even root makes nothing), under a regular file, the file itself, a
    folder nobody can write (/proc: chmod does not stop root), a file that is not there."""
    plain = tmp_path / "a-file"
    plain.write_text("")
    if kind == "out":
        return [
            ("/proc/x", "cannot be created in /proc ("),
            ("/proc/x/y", "cannot be created in /proc ("),
            (f"{plain}/x", f"cannot be created: {plain} is a file, not a folder"),
            (str(plain), "is a file, not a folder"),
            ("/proc", "is not writable ("),
        ]
    if kind == "folder":
        return [
            ("/proc/x", "does not exist"),
            (f"{plain}/x", f"does not exist ({plain} is not a folder)"),
            (str(plain), "is a file, not a folder"),
            (str(tmp_path / "missing"), "does not exist"),
        ]
    return [
        (str(tmp_path / "missing.toml"), "does not exist"),
        (str(tmp_path), "is a folder, not a file"),
        (f"{plain}/x.toml", f"does not exist ({plain} is not a folder)"),
        ("/proc/x", "does not exist"),
    ]


def _argv(command: str, option: str, value: str, study: Path) -> list[str]:
    if option == "STUDY.toml":
        return [command, value]
    return [command, *([str(study)] if command == "sweep" else []), option, value]


@pytest.mark.parametrize("command, option, kind", PATH_ARGUMENTS)
@pytest.mark.parametrize("parse_only", [False, True], ids=["run", "parse-only"])
def test_every_path_argument_is_refused_in_one_line_before_any_work(
    tmp_path, capsys, nothing_runs, command, option, kind, parse_only
):
    study = tmp_path / "study.toml"
    study.write_text("")
    for value, said in _bad_paths(tmp_path, kind):
        argv = _argv(command, option, value, study)
        with pytest.raises(SystemExit) as done:
            cli.main(["--parse-only", *argv] if parse_only else argv)
        err = capsys.readouterr().err
        assert done.value.code == 2, (argv, err)
        assert err == f"dyadfmu {command}: error: {option} {value}: {said}" + err.split(said)[1]
        assert err.count("\n") == 1 and said in err, (argv, err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-file", "study.toml"]


@pytest.mark.parametrize("command, option, kind", PATH_ARGUMENTS)
def test_a_usable_path_passes_and_checking_it_makes_nothing(
    tmp_path, capsys, command, option, kind
):
    study = tmp_path / "study.toml"
    study.write_text("")
    value = {"out": tmp_path / "new" / "deep", "folder": tmp_path, "file": study}[kind]
    assert cli.main(["--parse-only", *_argv(command, option, str(value), study)]) == 0
    assert not (tmp_path / "new").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.toml"]


def test_a_path_that_fails_during_the_work_is_one_line_too(tmp_path, capsys, monkeypatch):
    """A folder removed, or a disk filled, after the check: one line, status 2."""

    def vanished(args):
        raise FileNotFoundError(2, "No such file or directory", str(args.out / "x.csv"))

    monkeypatch.setattr(cli, "_study", vanished)
    assert cli.main(["study", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err == f"dyadfmu study: error: {tmp_path / 'x.csv'}: No such file or directory\n"


@pytest.mark.parametrize(
    "args, said",
    [
        (["--out", "/proc/x"], "scene.py: error: --out /proc/x: cannot be created in /proc ("),
        (["--out", "{file}/x"], "scene.py: error: --out {file}/x: cannot be created: {file} is"),
        (["--out", "{file}"], "scene.py: error: --out {file}: is a file, not a folder"),
        (["--out", "/proc"], "scene.py: error: --out /proc: is not writable ("),
    ],
)
def test_the_scene_generator_refuses_an_output_folder_in_one_line(tmp_path, args, said):
    plain = tmp_path / "a-file"
    plain.write_text("")
    args = [a.replace("{file}", str(plain)) for a in args]
    scene = paths.ROOT / "tests" / "scenes" / "balance.toml"
    done = subprocess.run(
        [sys.executable, str(paths.ROOT / "modelDescription" / "scene.py"), str(scene), *args],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith(said.replace("{file}", str(plain))), done.stderr


@pytest.mark.parametrize(
    "scene, said", [("{tmp}/none.toml", "does not exist"), ("{tmp}", "is a folder")]
)
def test_the_scene_generator_refuses_a_scene_file_it_cannot_read_in_one_line(tmp_path, scene, said):
    scene = scene.replace("{tmp}", str(tmp_path))
    done = subprocess.run(
        [sys.executable, str(paths.ROOT / "modelDescription" / "scene.py"), scene, "--check"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert (
        done.returncode == 2
        and done.stderr == f"scene.py: error: {scene}: {said}" + (done.stderr.split(said)[1])
    )
    assert done.stderr.count("\n") == 1


def test_parse_only_checks_and_runs_nothing(tmp_path, capsys, no_work):
    assert cli.main(["--parse-only", "run", "four-bar", "--steps", "36"]) == 0
    assert "--quik" in _refused(["--parse-only", "study", "--quik"], capsys)
    assert "--quik" in _refused(["--parse-only", "scenes", "--quik"], capsys)
    assert "--fmi-version" in _refused(["--parse-only", "cosim", "--fmi-version", "4"], capsys)
    assert cli.main(["--parse-only", "cosim", "--quick"]) == 0


@pytest.mark.parametrize("option", ["--sizes", "--write", "--chain"])
@pytest.mark.parametrize("value", ["0", "-3", "x"])
def test_scene_bench_refuses_a_bad_size_by_name(option, value, capsys):
    said = _refused(["scene-bench", option, value], capsys)
    assert f"argument {option}: " in said and value in said


def test_scene_bench_refuses_a_chain_the_generator_would_refuse(capsys):
    said = _refused(["scene-bench", "--chain", "201"], capsys)
    assert "argument --chain: must be from 1 to 200, got 201" in said


def test_sweep_refuses_a_bad_worker_count(capsys):
    assert "argument --workers: must be from 0 to 256, got -1" in _refused(
        ["sweep", "x.toml", "--workers", "-1"], capsys
    )


def test_every_command_has_a_description(capsys):
    for command in ("list", "run", "study", "speed", "sweep", "scene"):
        with pytest.raises(SystemExit):
            cli.main([command, "--help"])
        usage, _, rest = capsys.readouterr().out.partition("\n\n")
        assert not rest.startswith("positional arguments") and not rest.startswith("options")


# ---- the wrappers: arguments checked before the build ---------------------------------


def _fake_machine(tmp_path: Path) -> tuple[dict, Path]:
    """An environment in which every build tool is a stub that logs its call and fails, `id`
    says the user is not root (nothing is installed), and the venv is one whose dyadfmu is
    this checkout's: a wrapper that reaches its build leaves a line in the log."""
    stubs, log = tmp_path / "bin", tmp_path / "calls.log"
    stubs.mkdir(parents=True)
    for tool in ("cmake", "cc", "make", "pkg-config", "valgrind", "ctest", "id"):
        body = "echo 1000" if tool == "id" else f'echo "{tool} $*" >> "{log}"; exit 97'
        (stubs / tool).write_text(f"#!/bin/sh\n{body}\n")
        (stubs / tool).chmod(0o755)
    venv = tmp_path / "venv"
    (venv / "bin").mkdir(parents=True)
    (venv / "bin" / "python").symlink_to(sys.executable)
    dyadfmu = venv / "bin" / "dyadfmu"
    dyadfmu.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m dyadfmu "$@"\n')
    dyadfmu.chmod(0o755)
    (venv / ".dyadfmu-installed").touch()  # newer than pyproject.toml: no pip
    env = dict(
        os.environ,
        PATH=f"{stubs}:{os.environ['PATH']}",
        DYADFMU_VENV=str(venv),
        PYTHONPATH=os.pathsep.join(filter(None, [str(SCRIPTS), os.environ.get("PYTHONPATH")])),
    )
    return env, log


def _wrapper(tmp_path: Path, script: str, *args: str) -> tuple[subprocess.CompletedProcess, str]:
    env, log = _fake_machine(tmp_path)
    done = subprocess.run(
        [str(SCRIPTS / script), *args], capture_output=True, text=True, env=env, timeout=120
    )
    return done, log.read_text() if log.exists() else ""


@pytest.mark.parametrize(
    "script,args,said",
    [
        ("run-study", ["--quik"], "unrecognized arguments: --quik"),
        ("run-main", ["four-bar", "--steps", "x"], "argument --steps: not a whole number"),
        ("run-main", ["four-bra"], "unknown mechanism four-bra"),
        ("run-cosim", ["--fmi-version", "4"], "argument --fmi-version"),
        ("run-scenes", ["--quik"], "unrecognized arguments: --quik"),
        ("run-sweep", ["x.toml", "--workers", "-1"], "argument --workers"),
    ],
)
def test_a_wrapper_refuses_a_bad_argument_before_it_builds(tmp_path, script, args, said):
    done, calls = _wrapper(tmp_path, script, *args)
    assert done.returncode == 2, done.stderr
    assert said in done.stderr
    assert "cmake" not in calls and "building" not in done.stderr


WRAPPERS = ["run-main", "run-study", "run-cosim", "run-scenes", "run-sweep"]


@pytest.mark.parametrize("script", WRAPPERS)
def test_a_wrapper_answers_help_anywhere_without_building(tmp_path, script):
    done, calls = _wrapper(tmp_path, script, "x.toml", "--quick", "-h")
    assert done.returncode == 0 and done.stdout.startswith(f"usage: scripts/{script}")
    assert calls == ""


@pytest.mark.parametrize(
    "script, args, said",
    [
        ("run-main", ["--out", "/proc/x"], "dyadfmu run: error: --out /proc/x: cannot be created"),
        ("run-study", ["--out", "/proc/x"], "dyadfmu study: error: --out /proc/x: cannot be"),
        ("run-cosim", ["--out", "{file}/x"], "dyadfmu cosim: error: --out {file}/x: cannot be"),
        ("run-scenes", ["--build", "{file}"], "dyadfmu scenes: error: --build {file}: is a file"),
        (
            "run-sweep",
            ["{tmp}/none.toml"],
            "dyadfmu sweep: error: STUDY.toml {tmp}/none.toml: does",
        ),
        ("run-sweep", ["{tmp}"], "dyadfmu sweep: error: STUDY.toml {tmp}: is a folder, not a file"),
        ("run-fuzz", ["--build", "/proc/x"], "run-fuzz: error: --build /proc/x: cannot be created"),
        (
            "run-fuzz",
            ["--build", "{file}/x"],
            "run-fuzz: error: --build {file}/x: cannot be created",
        ),
    ],
)
def test_a_wrapper_refuses_a_bad_path_in_one_line_before_it_builds(tmp_path, script, args, said):
    plain = tmp_path / "a-file"
    plain.write_text("")

    def filled(text: str) -> str:
        return text.replace("{file}", str(plain)).replace("{tmp}", str(tmp_path))

    done, calls = _wrapper(tmp_path / "machine", script, *map(filled, args))
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith(filled(said)) and done.stderr.count("\n") == 1, done.stderr
    assert calls == "" and "Traceback" not in done.stderr


def test_a_wrapper_with_good_arguments_goes_on_to_build(tmp_path, monkeypatch):
    """(On a checkout of its own, whose build/ is not configured: the stub cmake
    configures it, and fails.)"""
    (tmp_path / "checkout").mkdir()
    monkeypatch.setenv("DYADFMU_ROOT", str(tmp_path / "checkout"))
    done, calls = _wrapper(tmp_path, "run-main", "four-bar", "--steps", "36")
    assert done.returncode == 97 and calls.startswith("cmake "), (done.stderr, calls)
    assert "failed" in done.stderr.splitlines()[-1]


def _build_in(root: Path, build: Path, env: dict, *options: str) -> subprocess.CompletedProcess:
    """dyadfmu_build of scripts/env.sh on the checkout `root`, into `build`."""
    script = f'source "{SCRIPTS / "env.sh"}" && dyadfmu_build "{build}" {" ".join(options)}'
    return subprocess.run(
        ["bash", "-c", script], capture_output=True, text=True, env=dict(env, DYADFMU_ROOT=root)
    )


def test_a_build_no_source_is_newer_than_is_left_as_it_is(tmp_path):
    """dyadfmu_build: configured and built the first time, then nothing until a source
    changes (only built then: make configures again where it must), configured again for
    new options; a line per FMU packaged, the rest in build.log."""
    env, log = _fake_machine(tmp_path)
    (tmp_path / "bin" / "cmake").write_text(
        f'#!/bin/sh\necho "cmake $*" >> "{log}"\n'
        'echo "[ 50%] Packaging x_fmi2.fmu"\necho "compiling x.c"\n'
    )
    root, build = tmp_path / "checkout", tmp_path / "build"
    for folder in ("src", "fmu", "modelDescription", "tests"):
        (root / folder).mkdir(parents=True)
    (root / "CMakeLists.txt").write_text("")
    (root / "LICENSE").write_text("")
    build.mkdir()
    (build / "CMakeCache.txt").write_text("")

    def calls() -> list[str]:
        text = log.read_text() if log.exists() else ""
        log.write_text("")
        return [line.split()[1] for line in text.splitlines()]

    os.utime(root / "src", (1, 1))  # sources older than the first build
    done = _build_in(root, build, env, "-DX=1")
    assert done.returncode == 0, done.stderr
    assert calls() == ["-S", "--build"] and "== [50%] packaged x_fmi2.fmu" in done.stderr
    assert "compiling x.c" in (build / "build.log").read_text()
    assert "compiling" not in done.stderr
    done = _build_in(root, build, env)  # no options: those of the last build
    assert calls() == [] and "is up to date" in done.stderr
    (root / "src" / "dyad_new.c").write_text("")
    assert _build_in(root, build, env).returncode == 0 and calls() == ["--build"]
    assert _build_in(root, build, env, "-DX=1").returncode == 0 and calls() == []
    assert _build_in(root, build, env, "-DX=2").returncode == 0 and calls() == ["-S", "--build"]
    # a product of the build removed: built again
    (build / "fmus").mkdir()
    (build / "fmus" / "x_fmi2.fmu").write_text("")  # as if the build had made it
    again = dict(env, DYADFMU_REBUILD="1")
    assert _build_in(root, build, again).returncode == 0 and calls() == ["--build"]
    assert _build_in(root, build, env).returncode == 0 and calls() == []
    (build / "fmus" / "x_fmi2.fmu").unlink()
    done = _build_in(root, build, env)
    assert done.returncode == 0 and calls() == ["--build"], done.stderr
    # a build that fails (the compiler, say) leaves the last whole build's stamp: the call
    # after it builds again, without configuring (its options are still known), and a
    # failure that never reached the compiler costs the next build nothing
    (tmp_path / "bin" / "cmake").write_text(f'#!/bin/sh\necho "cmake $*" >> "{log}"\nexit 3\n')
    (root / "src" / "dyad_newer.c").write_text("")
    assert _build_in(root, build, env).returncode == 3 and calls() == ["--build"]
    assert (build / ".dyadfmu-built").read_text() == "options: -DX=2"
    assert _build_in(root, build, env).returncode == 3 and calls() == ["--build"]


def test_a_build_is_made_by_the_cmake_that_configured_it(tmp_path):
    """Another CMake first on PATH (the venv's, where it is activated) would configure the
    build again and make every object anew: dyadfmu_build runs the one its cache names, for
    the build and for new options, and the first on PATH only where there is none."""
    env, log = _fake_machine(tmp_path)  # its cmake on PATH logs "cmake ..." and fails
    configured = tmp_path / "configured" / "cmake"
    configured.parent.mkdir()
    configured.write_text(f'#!/bin/sh\necho "configured $*" >> "{log}"\n')
    configured.chmod(0o755)
    root, build = tmp_path / "checkout", tmp_path / "build"
    for folder in ("src", "fmu", "modelDescription", "tests"):
        (root / folder).mkdir(parents=True)
    build.mkdir()
    (build / "CMakeCache.txt").write_text(f"CMAKE_COMMAND:INTERNAL={configured}\n")
    (build / ".dyadfmu-built").write_text("options: -DX=1")
    for options, wanted in (((), ["--build"]), (("-DX=2",), ["-S", "--build"])):
        log.write_text("")
        done = _build_in(root, build, dict(env, DYADFMU_REBUILD="1"), *options)
        assert done.returncode == 0, done.stderr
        calls = [line.split()[:2] for line in log.read_text().splitlines()]
        assert calls == [["configured", w] for w in wanted], calls
    (build / "CMakeCache.txt").write_text("")
    log.write_text("")
    assert _build_in(root, build, dict(env, DYADFMU_REBUILD="1")).returncode == 97
    assert log.read_text().startswith("cmake --build")


@pytest.mark.parametrize("args", [["--quick"], ["extra"], ["--help-me"], ["--serial", "-s"]])
def test_run_tests_refuses_every_argument_but_serial_and_help(tmp_path, args):
    done, calls = _wrapper(tmp_path, "run-tests", *args)
    assert done.returncode == 2 and f"unknown argument '{args[-1]}'" in done.stderr
    assert done.stderr.splitlines()[-1] == "usage: scripts/run-tests [--serial]" and calls == ""
    assert _wrapper(tmp_path / "h", "run-tests", "-h")[0].stdout.startswith("usage:")


# ---- the fuzz run and its driver ------------------------------------------------------


@pytest.mark.parametrize(
    "args,said",
    [
        (["--steps", "abc"], "--steps must be a whole number of at least 1"),
        (["--steps", "1e3"], "--steps must be a whole number of at least 1"),
        (["--steps", "-5"], "not '-5'"),
        (["--steps", "0"], "--steps must be a whole number of at least 1"),
        (["--steps"], "--steps needs a value"),
        (["--seed", "xyz"], "--seed must be a whole number from 0 to 18446744073709551615"),
        (["--seed", "18446744073709551616"], "--seed must be a whole number"),
        (["--jobs", "0"], "--jobs must be a whole number of at least 1, "),
        (["--fmu"], "--fmu needs a value"),
    ],
)
def test_run_fuzz_refuses_a_bad_count_by_name(tmp_path, args, said):
    done, calls = _wrapper(tmp_path, "run-fuzz", "--build", str(tmp_path), *args)
    assert done.returncode == 2 and said.split(", ")[0] in done.stderr, done.stderr
    assert calls == ""


def test_run_fuzz_passes_good_counts_to_the_driver(tmp_path):
    build = tmp_path / "build"
    (build / "fmu").mkdir(parents=True)
    (build / "fmus").mkdir()
    with zipfile.ZipFile(build / "fmus" / "toy_fmi2.fmu", "w") as fmu:
        fmu.writestr("modelDescription.xml", "<fmiModelDescription/>")
    driver = build / "fmu" / "fmu_fuzz"
    driver.write_text('#!/bin/sh\necho "$*" > "$0.args"\necho "fuzz toy fmi2: 5 steps"\n')
    driver.chmod(0o755)
    env = dict(os.environ, PATH=os.environ["PATH"])
    done = subprocess.run(
        [str(SCRIPTS / "run-fuzz"), "--steps", "05", "--seed", "42", "--build", str(build)],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    args = (build / "fmu" / "fmu_fuzz.args").read_text().split()
    assert args[:4] == ["--steps", "5", "--seed", "42"]


def _fuzz_driver() -> Path:
    path = paths.build_dir() / "fmu" / "fmu_fuzz"
    if not path.is_file():
        pytest.fail(f"{path} is missing: build the fuzz driver first (scripts/run-tests does)")
    return path


@pytest.mark.parametrize(
    "args,said",
    [
        (["--steps", "abc"], "--steps must be a whole number from 1 to"),
        (["--steps", "1e3"], "not '1e3'"),
        (["--steps", "-5"], "not '-5'"),
        (["--steps", "0"], "--steps must be a whole number from 1 to"),
        (["--steps", "99999999999999999999"], "--steps must be a whole number"),
        (["--seed", "xyz"], "--seed must be a whole number from 0 to 18446744073709551615"),
        (["--seed", "-1"], "not '-1'"),
        (["--seed", "18446744073709551616"], "--seed must be a whole number"),
        (["--replay", "0x"], "--replay must be a whole number"),
        (["--steps"], "--steps needs a value"),
        (["--sleps", "5"], "unknown argument '--sleps'"),
    ],
)
def test_the_fuzz_driver_refuses_a_bad_count_by_name(args, said):
    done = subprocess.run(
        [str(_fuzz_driver()), "no-such-fmu", *args], capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 2 and said in done.stderr, (done.stdout, done.stderr)


def test_the_fuzz_driver_takes_a_good_count():
    """A good set of options gets past the parsing to the FMU (missing here): status 1."""
    done = subprocess.run(
        [str(_fuzz_driver()), "--steps", "10", "--seed", "0x1F", "no-such-fmu"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 1 and "no-such-fmu" in done.stdout + done.stderr


def test_the_command_line_imports_no_co_simulation_until_a_command_needs_one():
    """A sweep's or a study's process starts with the parser: the co-simulations, their
    mpmath references and matplotlib are imported by the commands that use them (each
    import a few tens of milliseconds of a sweep that takes a few hundred)."""
    probe = (
        "import sys; from dyadfmu import cli; cli.parser(); "
        "print([m for m in ('mpmath', 'matplotlib', 'dyadfmu.cosim.harness', "
        "'dyadfmu.cosim.scenes', 'dyadfmu.reference.newton_euler') if m in sys.modules])"
    )
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"
