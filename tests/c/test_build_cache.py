"""The C engine's build cache (vm/native.py, `library`): whatever lies in the cache is
checked before anything loads it, a damaged library is built again with a warning, a
cache folder that cannot be used is a warning and a temporary build (never a crash),
and $CC is a command line. `rl1c run --engine c` runs in a subprocess of its own: a
library that crashes the loader would take pytest with it."""

from __future__ import annotations

import hashlib
import os
import shlex
import shutil
import stat
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from support import SAMPLE, SAMPLE_SENSORS
from support.hostile import cache_attack, hostile_libraries

from rl1.vm import native

RL1C = Path(sys.executable).with_name("rl1c")

pytestmark = pytest.mark.skipif(not any(shutil.which(cc) for cc in ("gcc", "cc", "clang")),
                                reason="no C compiler (gcc, cc or clang) on this machine")

# A library that, once loaded, leaves a file behind: what a planted library could do.
PLANTED = r"""
#include <stdio.h>
__attribute__((constructor)) static void planted(void) {
    FILE *f = fopen(MARKER, "w");
    if (f) fclose(f);
}
"""


def run_engine_c(tmp_path: Path, **env: str | None) -> subprocess.CompletedProcess[str]:
    """`rl1c run sample.rob --engine c` with these environment variables (None: unset)."""
    environment = {**os.environ, "HOME": str(tmp_path / "home")}
    for name, value in env.items():
        if value is None:
            environment.pop(name, None)
        else:
            environment[name] = value
    return subprocess.run([str(RL1C), "run", str(SAMPLE), "--sensors", str(SAMPLE_SENSORS),
                           "--engine", "c", "--format", "json"], capture_output=True,
                          text=True, env=environment, cwd=tmp_path, timeout=300, check=False)


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> str:
    """What the run prints on the reference VM."""
    done = subprocess.run([str(RL1C), "run", str(SAMPLE), "--sensors", str(SAMPLE_SENSORS),
                           "--format", "json"], capture_output=True, text=True, check=False,
                          cwd=tmp_path_factory.mktemp("reference"))
    assert done.returncode == 0, done.stderr
    return done.stdout


def built_cache(tmp_path: Path) -> tuple[Path, Path]:
    """A cache with the library built in it by a first run: the cache, the library."""
    cache = tmp_path / "cache"
    done = run_engine_c(tmp_path, XDG_CACHE_HOME=str(cache))
    assert done.returncode == 0 and "rl1: warning" not in done.stderr, done.stderr
    libraries = list((cache / "rl1").glob("librl1vm-*.so"))
    assert len(libraries) == 1
    return cache, libraries[0]


def assert_intact(library: Path) -> None:
    recorded = library.with_name(library.name + native.DIGEST_SUFFIX).read_text("ascii")
    assert recorded.strip() == hashlib.sha256(library.read_bytes()).hexdigest()


def test_the_cache_folder_is_made_for_its_owner_alone(tmp_path: Path) -> None:
    cache, library = built_cache(tmp_path)
    assert stat.S_IMODE((cache / "rl1").stat().st_mode) == 0o700
    assert_intact(library)


@pytest.mark.parametrize("damage", ["truncated", "empty", "garbage"])
def test_a_damaged_library_is_built_again_with_a_warning(tmp_path: Path, reference: str,
                                                         damage: str) -> None:
    # A truncated library killed Python with SIGBUS in the loader (exit 135) on every
    # run; an empty one was reported as "file too short".
    cache, library = built_cache(tmp_path)
    data = library.read_bytes()
    library.write_bytes({"truncated": data[:len(data) // 3], "empty": b"",
                         "garbage": bytes(len(data))}[damage])
    done = run_engine_c(tmp_path, XDG_CACHE_HOME=str(cache))
    assert (done.returncode, done.stdout) == (0, reference), done.stderr
    assert "is damaged or was not built there" in done.stderr and str(library) in done.stderr
    assert_intact(library)
    again = run_engine_c(tmp_path, XDG_CACHE_HOME=str(cache))
    assert (again.returncode, again.stdout) == (0, reference)
    assert "rl1: warning" not in again.stderr


@pytest.mark.parametrize("digest", ["none", "of another library"])
def test_a_planted_library_never_runs(tmp_path: Path, reference: str, digest: str) -> None:
    cache, library = built_cache(tmp_path)
    marker = tmp_path / "the planted library ran"
    planted = tmp_path / "planted.c"
    planted.write_text(PLANTED, encoding="ascii")
    compiler = next(cc for cc in ("cc", "gcc", "clang") if shutil.which(cc))
    subprocess.run([compiler, "-shared", "-fPIC", f'-DMARKER="{marker}"', "-o", str(library),
                    str(planted)], check=True)
    recorded = library.with_name(library.name + native.DIGEST_SUFFIX)
    if digest == "none":
        recorded.unlink()
    done = run_engine_c(tmp_path, XDG_CACHE_HOME=str(cache))
    assert (done.returncode, done.stdout) == (0, reference), done.stderr
    assert not marker.exists()
    assert "is damaged or was not built there" in done.stderr
    assert_intact(library)


@pytest.mark.parametrize("place", ["XDG_CACHE_HOME=/dev/null", "HOME=/proc",
                                   "HOME=a file", "XDG_CACHE_HOME=a read-only folder"])
def test_a_cache_that_cannot_be_used_is_a_warning_and_a_temporary_build(
        tmp_path: Path, reference: str, place: str) -> None:
    name, value = place.split("=")
    if value == "a file":
        (tmp_path / "file").write_text("", encoding="ascii")
        value = str(tmp_path / "file")
    elif value == "a read-only folder":
        if os.geteuid() == 0:
            pytest.skip("root writes into read-only folders")
        (tmp_path / "read-only").mkdir(mode=0o500)
        value = str(tmp_path / "read-only")
    env = {name: value, **({"XDG_CACHE_HOME": None} if name == "HOME" else {})}
    done = run_engine_c(tmp_path, TMPDIR=str(tmp_path), **env)
    assert (done.returncode, done.stdout) == (0, reference), done.stderr
    assert "as the C VM's build cache" in done.stderr
    assert "building the C VM in a temporary folder" in done.stderr
    assert "Traceback" not in done.stderr
    assert not list(tmp_path.glob("rl1-vm-*"))  # the temporary build is gone at exit


def test_no_folder_at_all_is_a_clear_error(monkeypatch: pytest.MonkeyPatch) -> None:
    # tempfile falls back from an unusable TMPDIR to /tmp, and further: only a machine
    # with no writable folder at all gets here.
    def no_folder(prefix: str) -> str:
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tempfile, "mkdtemp", no_folder)
    with pytest.raises(native.BuildError, match=r"no folder to build the C VM in.*TMPDIR"):
        native.library(Path("/dev/null/cache"), warn=lambda message: None)


def test_a_relative_xdg_cache_home_is_ignored(tmp_path: Path, reference: str) -> None:
    done = run_engine_c(tmp_path, XDG_CACHE_HOME="relative")
    assert (done.returncode, done.stdout) == (0, reference), done.stderr
    assert not (tmp_path / "relative").exists()
    assert list((tmp_path / "home" / ".cache" / "rl1").glob("librl1vm-*.so"))


@pytest.mark.parametrize("unsafe", ["writable by others", "owned by another user"])
def test_a_cache_folder_not_the_users_alone_is_not_used(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, unsafe: str) -> None:
    cache = tmp_path / "cache"
    library = native.library(cache)
    if unsafe == "writable by others":
        cache.chmod(0o777)
    else:
        monkeypatch.setattr(os, "getuid", lambda: os.stat(cache).st_uid + 1)
    monkeypatch.setattr(native, "_ready", {})
    warnings: list[str] = []
    elsewhere = native.library(cache, warn=warnings.append)
    assert elsewhere != library and elsewhere.parent != cache
    expected = "other users may write to it" if unsafe == "writable by others" \
        else "owns it, not you"
    assert len(warnings) == 1 and expected in warnings[0] and str(cache) in warnings[0]


def test_cc_is_a_command_line_with_arguments(tmp_path: Path, reference: str) -> None:
    # CC="gcc -m32" was looked up as one command name, not found, and silently ignored.
    compiler = next(cc for cc in ("cc", "gcc", "clang") if shutil.which(cc))
    seen = tmp_path / "arguments"
    wrapper = tmp_path / "my cc"
    wrapper.write_text(f'#!/bin/sh\necho "$@" > {shlex.quote(str(seen))}\n'
                       f'exec {compiler} "$@"\n', encoding="ascii")
    wrapper.chmod(0o755)
    cc = f"{shlex.quote(str(wrapper))} -DRL1_GIVEN_IN_CC=1"
    done = run_engine_c(tmp_path, XDG_CACHE_HOME=str(tmp_path / "cache"), CC=cc)
    assert (done.returncode, done.stdout) == (0, reference), done.stderr
    assert "-DRL1_GIVEN_IN_CC=1" in seen.read_text(encoding="ascii")


@pytest.mark.parametrize(("cc", "message"), [
    ('gcc "', "is not a command line"),
    ("no-such-compiler -O2", "names 'no-such-compiler', which is no command here"),
])
def test_a_cc_that_cannot_be_used_is_a_clear_error(tmp_path: Path, cc: str,
                                                   message: str) -> None:
    done = run_engine_c(tmp_path, XDG_CACHE_HOME=str(tmp_path / "cache"), CC=cc)
    assert done.returncode == 2 and message in done.stderr, done.stderr
    assert "Traceback" not in done.stderr


def test_a_library_for_another_machine_is_a_clear_error(tmp_path: Path) -> None:
    # gcc -m32 builds a library this Python cannot load (or, without 32-bit headers,
    # none): either way a message naming the flag, exit status 2.
    if not shutil.which("gcc"):
        pytest.skip("no gcc")
    done = run_engine_c(tmp_path, XDG_CACHE_HOME=str(tmp_path / "cache"), CC="gcc -m32")
    assert done.returncode == 2, done.stderr
    assert "-m32" in done.stderr or "set CC to a compiler for this one" in done.stderr
    assert "Traceback" not in done.stderr


@settings(max_examples=6, deadline=None, suppress_health_check=list(HealthCheck))
@given(data=hostile_libraries())
def test_any_damage_to_the_cached_library_is_repaired(data: bytes, tmp_path: Path) -> None:
    # bench/hostile_fuzz.py runs the same attack for as long as asked.
    assert cache_attack(data, tmp_path) == []
