"""The files `rl1c new DIR` writes: a project as a user lays it out (docs/tutorial.md's
first program and world, with a goal), each file commented where its format allows.
tests/cli/test_new_command.py holds that its tests pass as written, and that `rl1c
check` and `rl1c sim` accept it."""

from __future__ import annotations

PROGRAM = "main.rob"

FILES: dict[str, str] = {
    PROGRAM: """\
' main.rob: follow the guidance line until the wall ahead is near, then stop.
' Camera down at the floor (CAM D), trace the line in mode 1 (TRC 1), both wheels at
' speed 4 (MOV 4,4 returns at once; the vehicle keeps moving). The loop :10 waits half
' a second, reads the front ultrasonic sensor (ULT A, cm) less 40 into A, and goes
' round while A > 0. Then stop, stop tracing, hold the axes and end.
' The language: rl1c docs language. Check it: rl1c check main.rob
(CAM D); (TRC 1); (MOV 4,4)
:10 (TIM 5); A=(ULT A)-40; ?A>#10
(MOV 0,0); (TRC 0)
(HLD); (END)
""",
    "main.world.toml": """\
# The world main.rob runs in on the simulator (every key: rl1c docs simulator).
# Run it: rl1c sim main.rob --world main.world.toml --svg run.svg
# How often it works: rl1c sim main.rob --world main.world.toml --runs 100
# Units: cm, degrees and seconds.

noise = true            # the sensors' and wheels' imperfections, at their defaults

[floor]                 # a corridor 6 m by 3 m
size = [600, 300]

[start]                 # on the guidance line, facing along it
x = 60
y = 150
heading = 0

[[lines]]               # the guidance line: it bends once
name = "guide"
points = [[0, 150], [250, 150], [600, 200]]

[[walls]]               # the wall at the corridor's end, which ULT A sees
name = "end wall"
points = [[580, 0], [600, 0], [600, 300], [580, 300]]

# What the program is to achieve; rl1c sim says `goal met` or which part was missed.
[goal]
deadline = 60           # s: the run has ended by then

[goal.end]              # where the vehicle's centre is when the run ends
name = "stopped before the wall"
points = [[460, 150], [560, 150], [560, 230], [460, 230]]
""",
    "main.sensors.toml": """\
# A sensor script: what each sensing call reads, in order, for rl1c run (every key:
# rl1c docs sensors). Run it: rl1c run main.rob --sensors main.sensors.toml
# What (ULT A) reads, call by call: the wall comes nearer.
"ULT A" = [120, 80, 45, 38]
""",
    "main.tests.toml": """\
# The project's tests: rl1c test runs every *.tests.toml file below the folder it is
# given (the current one by default); every key: rl1c docs spec/tests.md.
# Paths are from this file's folder.

[[test]]
name = "main.rob stops before the wall"
program = "main.rob"
world = "main.world.toml"
seed = 0                          # the noise's seed: this run is rl1c sim --seed 0's
expect.goal = "met"
expect.calls = ["MOV 0,0", "HLD"]

[[test]]
name = "main.rob stops when the sensor reads under 40 cm"
program = "main.rob"
sensors = "main.sensors.toml"
expect.ends = "normally"
expect.variables = { A = -2 }     # 38 - 40: the last reading less 40
expect.calls = ["ULT A", "MOV 0,0"]

[[test]]
name = "main.rob succeeds in at least 95 % of 20 noisy runs"
program = "main.rob"
world = "main.world.toml"
expect.success = { runs = 20, at_least = 0.95 }
""",
    "rl1.toml": """\
# The options of rl1c check that this project shares (rl1c docs commands).
[check]
warnings-as-errors = true         # a warning fails the check, as in CI
# select = ["W"]                  # report only these warnings (codes or prefixes)
# ignore = ["W0603"]              # never these
""",
    ".vscode/tasks.json": """\
// VS Code's tasks (Terminal: Run Task): rl1c on this project. The problem matcher
// $rl1c, of the RL/I extension, puts rl1c check's problems in the Problems view.
{
  "version": "2.0.0",
  "tasks": [
    {
      "label": "rl1c check",
      "type": "process",
      "command": "rl1c",
      "args": ["check", "--format", "concise", "."],
      "problemMatcher": ["$rl1c"],
      "group": "build"
    },
    {
      // Every *.tests.toml file's tests; --junit FILE also writes JUnit XML.
      "label": "rl1c test",
      "type": "process",
      "command": "rl1c",
      "args": ["test"],
      "group": "test"
    },
    {
      // One run on the simulator, and a picture of it in run.svg.
      "label": "rl1c sim",
      "type": "process",
      "command": "rl1c",
      "args": ["sim", "main.rob", "--world", "main.world.toml", "--svg", "run.svg"]
    }
  ]
}
""",
    ".vscode/launch.json": """\
// VS Code's debugger configurations (Run and Debug): rl1-dap, the RL/I debugger.
// level 0 compiles without optimization, so that every line keeps its own code to stop
// on; breakpoints go on lines, and on calls (IMG, CAM P) as function breakpoints.
{
  "version": "0.2.0",
  "configurations": [
    {
      "type": "rl1",
      "request": "launch",
      "name": "Debug main.rob in its world",
      "program": "${workspaceFolder}/main.rob",
      "world": "${workspaceFolder}/main.world.toml",
      "seed": 0,
      "level": 0,
      "stopOnEntry": true
    },
    {
      "type": "rl1",
      "request": "launch",
      "name": "Debug main.rob on the sensor script",
      "program": "${workspaceFolder}/main.rob",
      "sensors": "${workspaceFolder}/main.sensors.toml",
      "level": 0,
      "stopOnEntry": true
    }
  ]
}
""",
    ".gitignore": """\
# What rl1c writes: compiled programs and pictures of runs.
*.ilc
*.svg
*.html
""",
}
