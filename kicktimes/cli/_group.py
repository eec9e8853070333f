"""The ``kicktimes`` command group and what every command shares: one-line errors naming
the option, plain numbers, the real-number parameter type."""


from __future__ import annotations

import contextlib
import math
import re

import click

from kicktimes import __version__

# numpy 2 reprs ("np.float64(-2.0)") leak into messages built with !r
_NUMPY_REPR = re.compile(r"\bnp\.(?:float|int|uint|bool_?)\d*\((.*?)\)")


def option(*param_decls, **attrs):
    """`click.option` that shows its default in ``--help`` (every kicktimes option does)."""
    return click.option(*param_decls, show_default=True, **attrs)


def _plain(message: str, options: dict | None = None) -> str:
    """``message`` with numpy scalar reprs unwrapped and a leading library argument name
    replaced by its command-line option (``t_max must ...`` -> ``--t-max must ...``)."""
    message = _NUMPY_REPR.sub(r"\1", message)
    for name, option in (options or {}).items():
        pattern = rf"^{re.escape(name)}(?=[\s:\[]|$)"
        if re.match(pattern, message):
            return re.sub(pattern, option, message, count=1)
    return message


def _os_message(exc: OSError) -> str:
    """One line for a file-system error: what failed and on which path."""
    what = exc.strerror or str(exc)
    if exc.filename is not None:
        return f"{what}: {exc.filename}"
    return what


@contextlib.contextmanager
def _cli_errors(options: dict | None = None):
    """Turn library and file-system errors into one-line click errors."""
    from kicktimes.experiment.store import StoreLockedError

    try:
        yield
    except click.ClickException:
        raise
    except OSError as exc:
        raise click.ClickException(_plain(_os_message(exc), options)) from None
    except (ValueError, TypeError, ImportError, StoreLockedError, RuntimeError) as exc:
        raise click.ClickException(_plain(str(exc), options)) from None


class _Real(click.ParamType):
    """A finite float in an open interval, checked by click so errors name the option."""

    name = "float"

    def __init__(self, low=None, high=None):
        self.low, self.high = low, high

    def convert(self, value, param, ctx):
        if isinstance(value, float):
            x = value
        else:
            try:
                x = float(value)
            except (TypeError, ValueError):
                self.fail(f"{value!r} is not a number", param, ctx)
        if not math.isfinite(x):
            self.fail(f"must be finite, got {x}", param, ctx)
        if (self.low is not None and x <= self.low) or (self.high is not None and x >= self.high):
            lo = "-inf" if self.low is None else f"{self.low:g}"
            hi = "inf" if self.high is None else f"{self.high:g}"
            self.fail(f"must lie in ({lo}, {hi}), got {x:g}", param, ctx)
        return x


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="kicktimes")
def main():
    """kicktimes: collision-time processes in circular billiards."""
    # the command owns its process: freed arrays are kept for reuse instead of being
    # returned to the system and faulted in again by the next kernel call, and the cyclic
    # garbage collector runs less often until the command ends (the sweep's and the
    # report's forked workers inherit both; see kicktimes.memory)
    from kicktimes.memory import fewer_collections, keep_freed_memory

    keep_freed_memory()
    click.get_current_context().with_resource(fewer_collections())


