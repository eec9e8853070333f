"""The ``kicktimes`` command line (click).

Errors reach the user as one line naming the command-line option (``--radius``, not the
library's ``r``), with plain numbers; file-system errors (read-only folder, full disk)
too, never as a traceback.

The commands live one module each and are registered here, explicitly, on the group
(:mod:`kicktimes.cli._group`): ``simulate``, ``schedule``, ``run``, ``presets``,
``report``, ``reproduce`` and ``analyze``.
"""

from kicktimes.cli._group import main
from kicktimes.cli.analyze import analyze_command
from kicktimes.cli.experiment import (
    presets_command,
    report_command,
    reproduce_command,
    run_command,
)
from kicktimes.cli.schedule import schedule_command
from kicktimes.cli.simulate import simulate_command

for _command in (simulate_command, schedule_command, run_command, presets_command,
                 report_command, reproduce_command, analyze_command):
    main.add_command(_command)

__all__ = ["main"]
