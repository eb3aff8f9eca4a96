"""examples/fig4.rob on examples/fig4.world.toml: the robust Fig. 4 scene of
spec/simulator.md ("The paper's reading"), the stand on the right by round numbers, no
line but the guidance line, noise on. Its claims (the README's and the world file's)
are held here: the goal is met without noise, and seeded runs with noise succeed at the
rate the spec states."""

from __future__ import annotations

from pathlib import Path

from rl1.compiler.campaign import Task, campaign_seeds, run_one, task_for, wilson
from rl1.vm.defaults import DEFAULT_BUDGET
from rl1.vm.sim.world import NOISELESS, decode_world

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
PROGRAM = (EXAMPLES / "fig4.rob").read_text("utf-8")
WORLD = (EXAMPLES / "fig4.world.toml").read_bytes()


def fig4_task(world: bytes) -> Task:
    return task_for(PROGRAM, world, "fig4.world.toml", "vm", DEFAULT_BUDGET, "fig4.rob")


def test_fig4_is_listing_1_with_one_token_less_in_each_steering_correction() -> None:
    listing_1 = (EXAMPLES / "sample.rob").read_text("utf-8")
    code = [line for line in PROGRAM.splitlines() if not line.startswith("'")]
    printed = [line for line in listing_1.splitlines() if not line.startswith("'")]
    assert code == [line.replace("d=a<3+c>a<7", "d=a<3+c>7") for line in printed]
    assert sum(line != original for line, original in zip(code, printed, strict=True)) == 2


def test_the_world_is_noisy_and_without_the_invented_return_line() -> None:
    world = decode_world(WORLD, "fig4.world.toml")
    assert world.noise != NOISELESS
    assert [line.name for line in world.lines] == ["guide"]
    stand = world.stands[0]
    assert (stand.x, stand.y, stand.facing) == (390, 35, 135)


def test_without_noise_the_program_meets_its_goal() -> None:
    quiet = WORLD.replace(b"noise = true", b"noise = false")
    assert decode_world(quiet, "quiet.toml").noise == NOISELESS
    record = run_one(fig4_task(quiet), 0)
    assert record.success, record


def test_with_noise_it_succeeds_in_at_least_nine_runs_of_ten() -> None:
    # spec/simulator.md measured 97 of 100 (seeds 0..99); 40 of them keep the test short.
    # The lower end of the 95% interval of what this sample shows must clear 80%, and the
    # rate itself 90%: a change that breaks the scene's robustness fails here.
    task = fig4_task(WORLD)
    records = [run_one(task, seed) for seed in campaign_seeds(0, 40)]
    successes = sum(record.success for record in records)
    low, _ = wilson(successes, len(records))
    assert successes >= 36 and low > 0.8, [r for r in records if not r.success]
