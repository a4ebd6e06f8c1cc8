"""The C core as another project uses it: `cmake --install` of the core alone (FMUs, tests
and benchmark off) into a temporary prefix, then the consumer project tests/consumer/
(one RRT dyad solved and checked against its closed form and its equilibrium, built for
double and float, static and shared) built three ways and run:

- through the installed CMake package: find_package(dyadfmu) with CMAKE_PREFIX_PATH;
- through the installed pkg-config files alone: cc main.c $(pkg-config ... dyadfmu);
- through add_subdirectory of this checkout with no option set, which must bring the
  core alone and none of the project's warnings, build type, tests or FMUs.

Without CMake, a C compiler or pkg-config the tests skip, except under CI (CI=true), where
they fail (scripts/env.sh installs them).
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest
from dyadfmu import paths
from tool_checks import required_tool

CONSUMER = paths.ROOT / "tests" / "consumer"
#: The consumer's executables (tests/consumer/CMakeLists.txt) and the scalar each has.
PROGRAMS = {
    "consumer_double": "double",
    "consumer_float": "float",
    "consumer_shared": "double",
    "consumer_float_shared": "float",
}
HEADERS = [
    "angle.h",
    "batch.h",
    "dual.h",
    "dyad.h",
    "evaluation.h",
    "kinematics.h",
    "loaded.h",
    "types.h",
]


def _run(*command: str | Path, env: dict[str, str] | None = None) -> str:
    done = subprocess.run(
        [str(c) for c in command], capture_output=True, text=True, env=env, check=False
    )
    assert done.returncode == 0, (
        f"{' '.join(str(c) for c in command)} exited with {done.returncode}:\n"
        f"{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
    )
    return done.stdout


def _cmake_build(source: Path, build: Path, *options: str) -> None:
    _run(required_tool("cmake"), "-S", source, "-B", build, *options)
    _run("cmake", "--build", build, "-j", str(os.cpu_count() or 2))


def _check_programs(directory: Path) -> None:
    for program, real in PROGRAMS.items():
        out = _run(directory / program, real)
        assert f"consumer ({real})" in out and out.rstrip().endswith(": ok"), out


@pytest.fixture(scope="module")
def prefix(tmp_path_factory):
    """The core configured, built and installed alone into <tmp>/prefix."""
    required_tool("cc")
    tmp = tmp_path_factory.mktemp("install")
    _cmake_build(
        paths.ROOT,
        tmp / "build",
        "-DCMAKE_BUILD_TYPE=Debug",
        "-DDYADFMU_BUILD_FMUS=OFF",
        "-DDYADFMU_BUILD_TESTS=OFF",
        "-DDYADFMU_BUILD_BENCH=OFF",
    )
    _run("cmake", "--install", tmp / "build", "--prefix", tmp / "prefix")
    return tmp / "prefix"


def test_the_install_holds_the_headers_the_four_libraries_and_the_package_files(prefix):
    files = {p.relative_to(prefix).as_posix() for p in prefix.rglob("*") if not p.is_dir()}
    lib = next(p.name for p in prefix.iterdir() if p.name.startswith("lib"))
    expected = {f"include/dyadfmu/{h}" for h in HEADERS} | {
        f"{lib}/libdyadfmu.a",
        f"{lib}/libdyadfmu_float.a",
        f"{lib}/libdyadfmu.so",
        f"{lib}/libdyadfmu_float.so",
        f"{lib}/cmake/dyadfmu/dyadfmuConfig.cmake",
        f"{lib}/cmake/dyadfmu/dyadfmuConfigVersion.cmake",
        f"{lib}/cmake/dyadfmu/dyadfmuTargets.cmake",
        f"{lib}/pkgconfig/dyadfmu.pc",
        f"{lib}/pkgconfig/dyadfmu_float.pc",
    }
    assert expected <= files, sorted(expected - files)
    # The core alone: no executable, FMU or generated file.
    assert {f.split("/")[0] for f in files} == {"include", lib}, sorted(files)
    assert not [f for f in files if f.endswith(".fmu") or "/generated/" in f]
    float_pc = (prefix / lib / "pkgconfig" / "dyadfmu_float.pc").read_text()
    assert "-DDYAD_REAL_FLOAT" in float_pc
    assert "-DDYAD_REAL_FLOAT" not in (prefix / lib / "pkgconfig" / "dyadfmu.pc").read_text()


@pytest.fixture(scope="module")
def package_consumer(prefix, tmp_path_factory):
    """tests/consumer built through find_package(dyadfmu) on the installed tree."""
    build = tmp_path_factory.mktemp("consumer")
    _cmake_build(CONSUMER, build, f"-DCMAKE_PREFIX_PATH={prefix}")
    return build


def test_a_project_finds_the_installed_package_and_solves_in_double_and_float(
    prefix, package_consumer
):
    cache = (package_consumer / "CMakeCache.txt").read_text()
    assert f"dyadfmu_DIR:PATH={prefix}" in cache, "find_package did not use the installed tree"
    _check_programs(package_consumer)


@pytest.mark.parametrize("package, real", [("dyadfmu", "double"), ("dyadfmu_float", "float")])
def test_a_program_builds_with_pkg_config_alone_and_solves(prefix, tmp_path, package, real):
    pkg_config = required_tool("pkg-config")
    lib = next(p for p in prefix.iterdir() if p.name.startswith("lib"))
    env = {**os.environ, "PKG_CONFIG_PATH": str(lib / "pkgconfig")}
    env.pop("PKG_CONFIG_LIBDIR", None)
    flags = _run(pkg_config, "--cflags", "--libs", package, env=env).split()
    libdir = _run(pkg_config, "--variable=libdir", package, env=env).strip()
    program = tmp_path / f"consumer_{real}"
    warnings = ["-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror"]
    _run("cc", *warnings, "-o", program, CONSUMER / "main.c", *flags, f"-Wl,-rpath,{libdir}")
    out = _run(program, real)
    assert out.rstrip().endswith(": ok"), out


def test_a_project_includes_the_source_tree_with_no_option_and_gets_the_core_alone(tmp_path):
    required_tool("cc")
    build = tmp_path / "subdirectory"
    _cmake_build(CONSUMER, build, f"-DDYADFMU_SOURCE_DIR={paths.ROOT}")
    _check_programs(build)
    # Only the core's libraries were built: no test, benchmark, example or FMU.
    built = {p.name for p in (build / "dyadfmu").iterdir() if p.is_file()}
    assert not {"dyad_tests_double", "dyad_bench", "slider_crank"} & built, sorted(built)
    assert not (build / "dyadfmu" / "fmus").exists()


def test_the_consumer_refuses_a_program_built_for_the_other_scalar(package_consumer):
    done = subprocess.run(
        [str(package_consumer / "consumer_float"), "double"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 1 and "built with dyad_real = float" in done.stderr
