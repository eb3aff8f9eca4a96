"""RL/I reference virtual machine, devices and simulator."""
