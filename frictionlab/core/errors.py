"""Error types. Every message is one line that names the file, field or parameter at fault."""


class FrictionLabError(Exception):
    """Base class of every error frictionlab raises for bad input: the message is one complete line naming
    the file, field or parameter and what was expected (the command line prints it and exits with status 2).

    Attributes
    ----------
    args : tuple of str
        The message, one line: what was wrong and what was expected.

    Examples
    --------
    >>> import frictionlab as fl
    >>> try:
    ...     fl.get_law("no-such-law")
    ... except fl.FrictionLabError as exc:
    ...     print(str(exc).split(";")[0])
    unknown law 'no-such-law'
    """

    def __str__(self) -> str:
        # a name taken from a user's file (a TOML key, a CSV header) may hold a line break
        return super().__str__().replace("\r", "\\r").replace("\n", "\\n")


class UnitError(FrictionLabError):
    """A quantity or unit string that cannot be read or has the wrong dimension."""


class DatasetError(FrictionLabError):
    """A dataset file (CSV or TOML) that is missing, malformed or inconsistent."""


class RegistryError(FrictionLabError):
    """An unknown law name, or two laws registered under one name."""


class LawError(FrictionLabError):
    """A law plugin that is malformed or returns an unusable force."""


class ParameterError(FrictionLabError):
    """A law or scene parameter that is unknown, out of bounds or of the wrong unit."""


class SceneError(FrictionLabError):
    """A scene that cannot supply what a law or an effect asks for."""


class SolverError(FrictionLabError):
    """An unknown solver, or a solver that does not apply to this law and scene."""


class FitError(FrictionLabError):
    """A fit that failed: past its time budget, not converged, or a model that cannot be solved at the data
    (what the law, the data and the options given lead to; the reason says which)."""


class OutputError(FrictionLabError):
    """An output path that exists or cannot be written."""


class ClusterError(FrictionLabError):
    """A Dask cluster that cannot run the work: no scheduler answering, no worker, a lost scheduler, a task past
    its time limit (``compare --scheduler``)."""


class WorkerLost(FrictionLabError):
    """A worker process died without a result (killed, out of memory, a law plugin that ends its process)."""


class Terminated(BaseException):
    """The process received SIGTERM or SIGHUP (raised by the handler frictionlab installs while it runs,
    so that clean-up code runs: worker processes stopped, temporary output removed, locks released)."""

    @property
    def signum(self) -> int:
        return int(self.args[0]) if self.args and isinstance(self.args[0], int) else 15

    def word(self) -> str:
        """'terminated' (SIGTERM) or 'hung up' (SIGHUP)."""
        return "hung up" if self.signum == 1 else "terminated"
