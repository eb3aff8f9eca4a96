"""`rl1c sim`: run a program on the simulator (vm/sim, spec/simulator.md) and show the
run: its trace with the vehicle's pose, a top view (SVG) and a replay page (HTML)."""

from __future__ import annotations

import os
import sys
from typing import TYPE_CHECKING

import click

from rl1.compiler.files import SourceError, read_bounded
from rl1.compiler.reporting.render import ColorChoice, use_color
from rl1.vm.defaults import TRACE_CHOICES, Engine, TraceChoice

from .command import (
    PATH,
    Command,
    at_least_one,
    budget_option,
    choice_option,
    color_option,
    engine_option,
    force_option,
    message_line,
    or_none,
)
from .streams import PATH_ESCAPES, invalid_config, read_failure, same_file, write_file

if TYPE_CHECKING:
    from rl1.compiler.sweep import Axis
    from rl1.vm.sim.world import World

SECTION = "Simulation"
MAX_WORLD_BYTES = 4 * 2**20
WORLD_ROLE = "world file"
EXAMPLE_WORLD = "examples/sample.world.toml"


@click.command(cls=Command)
@click.argument("file", metavar="FILE", type=PATH)
@click.option("--world", metavar="FILE", type=PATH,
              help="required: the world file (TOML, spec/simulator.md): the floor, lines, "
                   f"marks, stands, walls, scenes and the vehicle, such as {EXAMPLE_WORLD}")
@click.option("--svg", "svg_file", metavar="FILE", type=PATH,
              help="write a top view of the run (the paper's Fig. 9) to FILE")
@click.option("--html", "html_file", metavar="FILE", type=PATH,
              help="write a page that replays the run, offline, to FILE")
@choice_option("--format", "sim_format", choices=("text", "json"), default="text",
               help="text: for people; json: one object with the pose track, for tools")
@click.option("--seed", type=click.IntRange(0, 2**32 - 1), default=None,
              help="the seed of the sensor noise (the world sets the noise; off by default) "
                   "and of the world's [vary] draws (default 0; a run without --seed draws "
                   "nothing: the world as written)")
@engine_option
@budget_option
@choice_option("--trace", "trace_choice", choices=TRACE_CHOICES, default=None,
               help="which calls to show, as `rl1c run --trace`: short: the first 40 and "
                    "the last 20 of a longer trace, with how many were left out; all; calls; "
                    "none. Default: short with --format text, all with json")
@click.option("--runs", type=str, default=None, callback=or_none(at_least_one), metavar="N",
              help="a campaign: run N times, with the seeds --seed, --seed + 1, ...; print "
                   "the success rate (95% Wilson interval) and the failures grouped by "
                   "kind and source line, each with the command that replays one")
@click.option("--jobs", type=str, default=None, callback=or_none(at_least_one), metavar="J",
              help="with --runs: the processes that make the runs (default: every core); "
                   "the results are the same for any J")
@click.option("--scheduler", metavar="ADDRESS",
              help="with --runs: make the runs on the Dask cluster of this scheduler "
                   "(tcp://HOST:8786; the extra rl1[cluster]) instead of local processes; "
                   "the same results")
@click.option("--sweep", "sweeps", metavar="KEY=A:B:N", multiple=True,
              help="with --runs, once or twice: a campaign at each point of the grid, KEY "
                   "(as [vary] names it: start.x, stands.NAME.x, vehicle.k1, noise.slip) "
                   "moved from the world's value by A to B in N steps; prints the success "
                   "rate of each point (and a heat map for two); without --runs, N = 1: "
                   "one run at that point")
@click.option("--out", "out_file", metavar="FILE", type=PATH,
              help="with --runs: write each run as a JSON line to FILE (- for standard "
                   "output, the summary then on standard error), in seed order, as the "
                   "runs finish")
@force_option
@color_option
def sim(file: str, world: str | None, svg_file: str | None, html_file: str | None,
        sim_format: str, seed: int | None, engine: Engine, budget: int,
        trace_choice: TraceChoice | None, runs: int | None, jobs: int | None,
        scheduler: str | None, sweeps: tuple[str, ...], out_file: str | None, force: bool,
        color: ColorChoice) -> int:
    """Run a program (.rob source, or an .ilc file) on the simulated vehicle and world.

    Prints each call with the device time, its source line and the vehicle's pose after
    it, how the run ended, the final variables, the device time and the instructions
    run. A safety stop (off the floor, a collision, the time limit) is a device fault.
    Exit status: 0 the program ended; 1 it has errors; 2 a usage problem or an
    unreadable or invalid file (the world file included); faults as `rl1c run`: 10
    argument out of range, 11 missing handler, 12 budget exhausted, 13 device error
    (safety stops included); 20 the program ended but missed the world's [goal].

    With --runs N, a campaign (a mode of `rl1c sim` rather than a command of its own:
    the same program, world, engine and budget, and each run is the `rl1c sim --seed`
    run it names): exit status 0 when it ran to its end, whatever the success rate;
    130 when stopped by Ctrl-C (143 by SIGTERM), after the summary of the runs made.
    The world's [vary] table draws for each run of a campaign, and for a run given
    --seed; --sweep runs the campaign at each point of a grid; --svg and --html then
    draw every run's path and failures (spec/simulator.md, "Varying the world")."""
    from rl1.compiler.simulation import Simulation, run_status
    from rl1.vm.sim.render import html, svg
    from rl1.vm.sim.world import WorldError, decode_world

    from .run_report import call_text
    from .running import run_file
    from .sim_report import render_json, render_text

    if world is None:
        raise click.UsageError("a simulation needs a world to run in: give --world FILE, a "
                               f"world file (TOML, spec/simulator.md) such as {EXAMPLE_WORLD}")
    refuse_picture_targets(svg_file, html_file, (file, world), out_file, runs is not None)
    if runs is None:
        for option, given in (("--jobs", jobs), ("--scheduler", scheduler),
                              ("--out", out_file)):
            if given is not None:
                raise click.UsageError(f"{option} is for a campaign of runs: give --runs N")
    elif jobs is not None and scheduler is not None:
        raise click.UsageError("--jobs counts local processes, and --scheduler gives the "
                               "runs to a cluster's workers: give one of them")
    else:
        if trace_choice is not None:
            raise click.UsageError("--trace shows one run, and --runs makes many: replay "
                                   "one run (the summary gives its command) with --trace")
        if sim_format != "text":
            raise click.UsageError("--format json shows one run: a campaign writes each "
                                   "run as a JSON line with --out FILE")
    try:
        world_bytes = read_bounded(world, MAX_WORLD_BYTES, "a world file")
        the_world = decode_world(world_bytes, world)
    except SourceError as error:
        raise read_failure(error, WORLD_ROLE) from None
    except WorldError as error:
        raise invalid_config(WORLD_ROLE, world, error,
                             "correct it as spec/simulator.md describes") from None
    axes = sweep_axes(sweeps, the_world, runs is not None)
    if runs is not None:
        from .sim_campaign import Pictures, Setting, run_campaign

        setting = Setting(file, world, seed or 0, runs, jobs or os.cpu_count() or 1, engine,
                          budget, scheduler, axes)
        return run_campaign(file, world_bytes, world, setting, out_file, color,
                            Pictures(svg_file, html_file, force))
    the_world = single_run_world(the_world, axes, seed)
    simulation = Simulation(the_world, seed or 0)
    device = simulation.device
    ran = run_file(file, device, engine, budget, color, "sim")
    if isinstance(ran, int):
        return ran
    result = ran.finished.result
    ending = simulation.end(result)
    ended_at, run_on, verdict = ending.ended_at, ending.run_on, ending.verdict
    title = f"{os.path.basename(file)} on {os.path.basename(world)}" + (
        "" if verdict is None else f": {verdict.headline()}")
    if svg_file is not None:
        picture = svg(the_world, device.sim.track, device.sim.events, title, device.trace,
                      device.sightings, verdict)
        write_file(svg_file, picture.encode("utf-8", PATH_ESCAPES), force=force,
                   role="SVG file")
    if html_file is not None:
        write_file(html_file, html(
            the_world, device.sim.track, device.sim.events, device.trace, title,
            device.sightings, lambda entry: call_text(entry.call, entry.args, entry.result),
            verdict).encode("utf-8", PATH_ESCAPES), force=force, role="HTML file")
    if sim_format == "json":
        sys.stdout.write(render_json(result, device, ran.finished.instructions, ended_at,
                                     run_on, trace_choice or "all", verdict))
    else:
        sys.stdout.write(render_text(ran, device, file, ended_at, run_on,
                                     trace_choice or "short",
                                     color=use_color(color, sys.stdout), verdict=verdict))
    return int(run_status(result, verdict)["exit_status"])


def sweep_axes(sweeps: tuple[str, ...], world: World, campaign: bool) -> tuple[Axis, ...]:
    """The axes of `--sweep`, checked against `world`; a usage error says what is wrong.
    Without --runs, each gives one point: the run's."""
    from rl1.compiler.sweep import check, parse_axis

    try:
        axes = tuple(parse_axis(text) for text in sweeps)
        check(world, axes)
    except ValueError as error:
        raise click.UsageError(f"--sweep: {error}") from None
    if not campaign and any(axis.count > 1 for axis in axes):
        raise click.UsageError("--sweep of more than one point is for a campaign: give "
                               "--runs N, or KEY=A:A:1 for one run at that point")
    return axes


def refuse_picture_targets(svg_file: str | None, html_file: str | None,
                           inputs: tuple[str, str], out: str | None, campaign: bool) -> None:
    """A usage error, before any run, for a picture that would replace the program or the
    world, the other picture or a campaign's JSON lines (`out`), or, for a `campaign`,
    that could not be written (its runs would be made for nothing; a single run's picture
    is refused as any output file is, after it). A device such as /dev/null may take
    every output."""
    others: dict[str, str | None] = {"--out": out}
    for option, target in (("--svg", svg_file), ("--html", html_file)):
        if target is None:
            continue
        if target == "-":
            raise click.UsageError(f"{option} writes a file, and standard output carries "
                                   f"the report: give {option} FILE")
        for role, name in zip(("program", "world file"), inputs, strict=True):
            if same_file(name, target):
                raise click.UsageError(f"{option} `{target}` is the {role} itself: give "
                                       "another path for the picture")
        stream = os.path.exists(target) and not os.path.isfile(target)  # /dev/null
        for other, taken in others.items():
            if not stream and taken is not None and (
                    os.path.realpath(taken) == os.path.realpath(target)):
                raise click.UsageError(f"{option} and {other} both name `{target}`: give "
                                       "each its own file")
        others[option] = target
        if not campaign:
            continue
        if os.path.isdir(target or "."):
            raise click.UsageError(f"{option} `{target}` is a folder: give the path of a "
                                   "file for the picture")
        if not os.path.isdir(os.path.dirname(os.path.abspath(target))):
            raise click.UsageError(f"{option} `{target}`: its folder does not exist; "
                                   "create it, or write the picture elsewhere")


def single_run_world(world: World, axes: tuple[Axis, ...], seed: int | None) -> World:
    """The world of a single run: at the point of `axes` (each of one point), and drawn
    from [vary] when --seed is given, each value drawn said on standard error."""
    from rl1.compiler.campaign import run_world as drawn_world

    offsets = tuple((axis.key, axis.first) for axis in axes)
    if seed is None:
        return world.moved(dict(offsets))
    world, values = drawn_world(world, offsets, seed)
    if values:
        drawn = ", ".join(f"{key} = {value:.6g}" for key, value in values.items())
        print(message_line(click.get_current_context().command_path, "note",
                           f"the world of seed {seed}: {drawn}"), file=sys.stderr)
    return world


COMMANDS = (sim,)
