"""`rl1c new DIR`: start a project (the files of project_template.py), all at once: they
are written into a temporary folder beside DIR, which is then renamed to DIR (or, for an
empty DIR that exists, whose entries are moved into it, each whole), so that a failure
leaves nothing half written, and nothing in DIR is ever replaced."""

from __future__ import annotations

import contextlib
import os

import click

from .command import PATH, Command, CommandError, Failure
from .project_template import FILES, PROGRAM
from .streams import cannot, file_problem, os_reason, problem_text, write_help

SECTION = "Projects"


@click.command(cls=Command)
@click.argument("folder", metavar="DIR", type=PATH)
def new(folder: str) -> int:
    """Start a project in the new folder DIR: a program, a world with a goal, a sensor
    script, a test file, an rl1.toml and VS Code's tasks and debugger configurations,
    each commented.

    Its tests pass as written: `cd DIR && rl1c test`. DIR must not exist, or be empty;
    its parent folder must exist. Exit status: 0 done; 2 DIR is not empty, or it cannot
    be written (nothing is written then)."""
    import shutil
    import tempfile

    if folder == "-":
        raise click.UsageError("DIR is a folder to create: give its path")
    target = os.path.abspath(folder)
    _refuse_unless_empty(folder, target)
    parent = os.path.dirname(target)
    try:
        building = tempfile.mkdtemp(dir=parent, prefix=f".{os.path.basename(target)}.",
                                    suffix=".tmp")
    except OSError as error:
        raise _cannot_create(folder, error) from None
    try:
        for name, text in FILES.items():
            path = os.path.join(building, name)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w", encoding="utf-8", newline="\n") as stream:
                stream.write(text)
        if os.path.isdir(target):
            _move_into(building, target)
        else:
            os.chmod(building, 0o777 & ~_umask())  # mkdtemp's folder is the owner's alone
            os.rename(building, target)
    except BaseException as error:  # Ctrl-C too: the temporary folder never stays
        with contextlib.suppress(OSError):
            shutil.rmtree(building)
        if not isinstance(error, OSError):
            raise
        if os.path.isdir(target) and os.listdir(target):  # filled in the meantime
            _refuse_unless_empty(folder, target)
        raise _cannot_create(folder, error) from None
    print(f"created {folder}: " + ", ".join(sorted(FILES)))
    here = f"cd {folder} && " if folder != "." else ""
    print(f"next: {here}rl1c test (its tests pass as written); rl1c sim {PROGRAM} --world "
          "main.world.toml --svg run.svg; then make the program yours")
    return 0


def _move_into(building: str, target: str) -> None:
    """Move the built files into the empty folder `target`, each whole, keeping the
    folder itself (it may be a shell's current folder, which a rename over it would
    leave behind); on a failure, the files moved are taken out again."""
    import shutil

    moved: list[str] = []
    try:
        for entry in sorted(os.listdir(building)):
            destination = os.path.join(target, entry)
            if os.path.lexists(destination):  # written there in the meantime
                raise FileExistsError(17, "a file appeared in it meanwhile", destination)
            os.rename(os.path.join(building, entry), destination)
            moved.append(destination)
        os.rmdir(building)
    except BaseException:  # Ctrl-C too: the folder is left as empty as it was
        for destination in moved:
            with contextlib.suppress(OSError):
                if os.path.isdir(destination) and not os.path.islink(destination):
                    shutil.rmtree(destination)
                else:
                    os.unlink(destination)
        raise


def _refuse_unless_empty(folder: str, target: str) -> None:
    if not os.path.lexists(target):
        return
    if not os.path.isdir(target):
        raise CommandError(f"`{folder}` exists and is no folder; give the "
                           "path of a new folder")
    try:
        entries = sorted(os.listdir(target))
    except OSError as error:
        raise _cannot_create(folder, error) from None
    if entries:
        shown = ", ".join(f"`{entry}`" for entry in entries[:3]) + (
            ", ..." if len(entries) > 3 else "")
        raise CommandError(f"`{folder}` is not empty (it holds {shown}); "
                           "rl1c new writes only into a new or empty folder, so that it "
                           "replaces nothing: give another path")


def _cannot_create(folder: str, error: OSError) -> Failure:
    return Failure(problem_text(file_problem(folder, cannot(
        "create", "project folder", folder, os_reason(error)),
        write_help(error, "check that its parent folder exists and is writable, or create "
                          "it elsewhere"))))


def _umask() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return umask


COMMANDS = (new,)
