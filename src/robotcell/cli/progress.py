"""A progress bar on stderr for long CLI jobs: it appears only after the job has run a while."""

from __future__ import annotations

import sys
import time
from contextlib import ExitStack

import click

#: Seconds after which a running job shows its progress bar.
PROGRESS_AFTER = 2.0


class DeferredProgress:
    """Callable ``(done, total)`` that draws a click progress bar on stderr once the job has run
    for :data:`PROGRESS_AFTER` seconds; ``stack`` closes the bar when the job ends."""

    def __init__(self, stack: ExitStack, label: str) -> None:
        self.stack, self.label = stack, label
        self.start = time.monotonic()
        self.bar = None
        self.shown = 0

    def __call__(self, done: int, total: int) -> None:
        if self.bar is None:
            if time.monotonic() - self.start < PROGRESS_AFTER or done >= total:
                return
            self.bar = self.stack.enter_context(click.progressbar(
                length=total, label=self.label, file=sys.stderr, show_pos=True))
        self.bar.update(done - self.shown)
        self.shown = done
