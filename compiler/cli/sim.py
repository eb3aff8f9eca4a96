"""`rl1c sim`: run a program on the simulator (vm/sim, spec/simulator.md) and show the
run: its trace with the vehicle's pose, a top view (SVG) and a replay page (HTML)."""

from __future__ import annotations

import os
import sys

import click

from rl1.compiler.files import SourceError, read_bounded
from rl1.compiler.frontend.source import Source
from rl1.compiler.reporting.render import EXIT_ERRORS, FileDiagnostics
from rl1.vm.faults import DEFAULT_BUDGET

from .command import PATH, Command, Failure, a_budget, choice_option
from .streams import emit, read_ilc, read_input, write_file

SECTION = "Simulation"
MAX_WORLD_BYTES = 4 * 2**20


@click.command(cls=Command)
@click.argument("file", metavar="FILE", type=PATH)
@click.option("--world", metavar="FILE", type=PATH, required=True,
              help="the world file (TOML, spec/simulator.md): the floor, lines, marks, "
                   "stands, walls, scenes and the vehicle")
@click.option("--svg", "svg_file", metavar="FILE", type=PATH,
              help="write a top view of the run (the paper's Fig. 9)")
@click.option("--html", "html_file", metavar="FILE", type=PATH,
              help="write a page that replays the run, offline")
@choice_option("--format", "sim_format", choices=("text", "json"), default="text",
               help="text: for people; json: one object with the pose track, for tools")
@click.option("--seed", type=click.IntRange(0, 2**32 - 1), default=0, show_default=True,
              help="the seed of the sensor noise (the world sets the noise; off by default)")
@choice_option("--engine", choices=("vm", "ast"), default="vm",
               help="vm: compile, then run on the reference VM; ast: interpret the source")
@click.option("--budget", type=str, default=str(DEFAULT_BUDGET), callback=a_budget,
              metavar="N", show_default=True,
              help="instructions (statements with --engine ast) before the watchdog stops "
                   "a runaway program")
def sim(file: str, world: str, svg_file: str | None, html_file: str | None, sim_format: str,
        seed: int, engine: str, budget: int) -> int:
    """Run a program (.rob source, or an .ilc file) on the simulated vehicle and world.

    Prints each call with the time and the vehicle's pose, how the run ended and the
    final variables. A safety stop (off the floor, a collision, the time limit) is a
    device fault. Exit status: 0 the program ended; 1 it has errors; 2 a usage problem
    or an unreadable or invalid file (the world file included); faults as `rl1c run`:
    10 argument out of range, 11 missing handler, 12 budget exhausted, 13 device error
    (safety stops included)."""
    from rl1.vm.faults import RunResult
    from rl1.vm.sim.device import SimDevice
    from rl1.vm.sim.render import html, svg
    from rl1.vm.sim.world import WorldError, decode_world
    from rl1.vm.verifier import VerifyError

    from .run import run_ilc, run_source
    from .sim_report import render_json, render_text

    try:
        the_world = decode_world(read_bounded(world, MAX_WORLD_BYTES, "a world file"), world)
    except (SourceError, WorldError) as error:
        raise Failure(f"error: {error}") from None
    device = SimDevice(the_world, seed=seed)
    if file.lower().endswith(".ilc"):
        if engine == "ast":
            raise click.UsageError("--engine ast interprets RL/I source; an .ilc file runs "
                                   "on the VM: leave out --engine, or run the .rob file")
        try:
            result = run_ilc(read_ilc(file), device, budget)
        except VerifyError as error:
            raise Failure(f"error: {file}: byte {error.offset}: {error.message}",
                          EXIT_ERRORS) from None
    else:
        source = read_input(file)
        if not isinstance(source, Source):
            return emit([source], "human", "auto", "sim", err=True)
        outcome = run_source(source.text, os.path.basename(source.name), device,
                             "ast" if engine == "ast" else "vm", budget)
        if not isinstance(outcome, RunResult):
            return emit([FileDiagnostics(source.name, source.text, outcome)], "human",
                        "auto", "sim", err=True)
        result = outcome
    run_on = None
    if result.fault is None:
        moving = device.sim.motion is not None
        device.sim.note("end", "the program ended" + (
            " with the vehicle moving: it runs on" if moving else ""))
        run_on = device.run_on()  # (END) leaves motion in effect: where does it go?
    elif device.fault is None:  # a safety stop has noted itself
        device.sim.note("fault", result.fault.message)
    title = f"{os.path.basename(file)} on {os.path.basename(world)}"
    if svg_file is not None:
        write_file(svg_file, svg(the_world, device.sim.track, device.sim.events,
                                 title).encode())
    if html_file is not None:
        calls = [(entry.time, entry.call
                  + (" " + ",".join(map(str, entry.args)) if entry.args else "")
                  + (" -> " + " ".join(map(str, entry.result)) if entry.result else ""))
                 for entry in device.trace]
        write_file(html_file, html(the_world, device.sim.track, device.sim.events, calls,
                                   title).encode())
    render = render_json if sim_format == "json" else render_text
    sys.stdout.write(render(result, device, run_on))
    return result.fault.kind.exit_status if result.fault is not None else 0


COMMANDS = (sim,)
