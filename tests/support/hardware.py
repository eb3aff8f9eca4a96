"""Hardware for tests that change what some callbacks do: `Relay` passes every callback
of the hardware interface (vm/hardware.py) to the `inner` hardware, so that a test's
misbehaving hardware overrides only the callbacks it changes."""

from __future__ import annotations

from dataclasses import dataclass

from rl1.vm.device import FormKey, LineLost
from rl1.vm.hardware import Answer, Blocking


@dataclass
class Relay:
    inner: Blocking

    def begin(self) -> Answer:
        return self.inner.begin()

    def call(self, form: FormKey, args: tuple[int, ...]) -> Answer:
        return self.inner.call(form, args)

    def start(self, form: FormKey, args: tuple[int, ...]) -> Answer:
        return self.inner.start(form, args)

    def poll(self) -> Answer:
        return self.inner.poll()

    def stop(self) -> Answer:
        return self.inner.stop()

    def end(self) -> Answer:
        return self.inner.end()

    @property
    def pending(self) -> LineLost | None:
        return self.inner.pending

    def take_event(self) -> LineLost | None:
        return self.inner.take_event()
