"""One door: ``pinmob analyze`` parses, calls the library and formats; the library checks each argument once.

The command line used to resolve the configuration name itself (``cli/common.py``) before the library did it
again (``Configuration``), and to check ``--rtol`` and ``--closure-tol`` before :func:`pinmob.analyze` checked
them again (``closure_tol`` a third time in ``Configuration``).
"""

from __future__ import annotations

import sys
from collections import Counter
from collections.abc import Callable
from typing import Any

import pytest

from pinmob.cli import main


def count_calls(monkeypatch: pytest.MonkeyPatch, calls: Counter[str], name: str, original: Callable[..., Any]) -> None:
    """Replace ``original`` by a wrapper counting its calls, in every pinmob module that holds it under ``name``."""

    def counted(*args: Any, **kwargs: Any) -> Any:
        calls[name] += 1
        return original(*args, **kwargs)

    for module in list(sys.modules.values()):
        if getattr(module, "__name__", "").startswith("pinmob") and getattr(module, name, None) is original:
            monkeypatch.setattr(module, name, counted)


@pytest.mark.parametrize(
    "argv",
    [
        ["analyze", "3-PRS", "--config", "home", "--rtol", "1e-7", "--closure-tol", "1e-5"],
        ["analyze", "3-PRS", "--config", "HOME"],
        ["analyze", "3-PRS", "--joints", "A_slider=0.3", "--closure-tol", "1e-5"],
    ],
)
def test_analyze_checks_each_argument_once(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], argv):
    """One ``pinmob analyze``: rtol checked once, closure_tol once (by the library), the name resolved by the library.

    On the old code: rtol twice with --rtol, closure_tol 14 to 15 times (twice at the door, then in every
    Configuration the generic-rank estimate built), and the name resolved by ``cli/common.py`` first."""
    import pinmob.analysis.entry_point  # noqa: F401  (loaded, so that its names are wrapped too)
    import pinmob.cli.analyze  # noqa: F401
    import pinmob.cli.common  # noqa: F401

    calls: Counter[str] = Counter()
    count_calls(monkeypatch, calls, "check_rtol", pinmob.screw.rank.check_rtol)
    count_calls(monkeypatch, calls, "check_closure_tol", pinmob.assembly.residual.check_closure_tol)
    resolve = pinmob.model.mechanism.Mechanism.configuration_name

    def counted_name(self: Any, name: str) -> str:
        caller = sys._getframe(1).f_globals["__name__"]
        calls["configuration_name in the CLI" if caller.startswith("pinmob.cli") else "configuration_name"] += 1
        return resolve(self, name)

    monkeypatch.setattr(pinmob.model.mechanism.Mechanism, "configuration_name", counted_name)
    assert main(argv) == 0, capsys.readouterr().err
    assert "DoF" in capsys.readouterr().out
    assert calls["check_rtol"] == 1
    assert calls["check_closure_tol"] == 1
    assert calls["configuration_name in the CLI"] == 0  # the library resolves the name, the CLI passes it on
    assert calls["configuration_name"] >= (0 if "--joints" in argv else 1)


def test_a_bad_argument_and_an_unknown_configuration_are_told_apart() -> None:
    """Both used to be a bare ConfigurationError; the subclasses carry what was wrong as data, and the library's
    messages name its Python parameters, not the command line's options."""
    import pickle

    import pinmob

    mech = pinmob.load("3-PRS")
    with pytest.raises(pinmob.ArgumentError) as bad:
        pinmob.analyze(mech, "home", closure_tol=1.0)
    assert isinstance(bad.value, pinmob.ConfigurationError)
    assert (bad.value.parameter, bad.value.value) == ("closure_tol", 1.0) and "--" not in str(bad.value)
    again = pickle.loads(pickle.dumps(bad.value))  # as a Dask worker sends it back
    assert (type(again), str(again), again.parameter, again.parameters) == (
        pinmob.ArgumentError,
        str(bad.value),
        "closure_tol",
        ("closure_tol",),
    )
    with pytest.raises(pinmob.ArgumentError, match=r"^the number of random restarts \(restarts\) must be") as neg:
        pinmob.analyze(mech, None, restarts=-1)
    assert neg.value.parameter == "restarts"
    with pytest.raises(pinmob.UnknownConfigurationError, match="did you mean 'home'") as unknown:
        pinmob.analyze(mech, "hme")
    assert isinstance(unknown.value, pinmob.ConfigurationError) and unknown.value.name == "hme"


def test_the_command_line_words_the_parameters_as_its_options(capsys: pytest.CaptureFixture[str]) -> None:
    """The library says ``restarts``; the command line prints ``--restarts`` (pinmob/cli/flags.py)."""
    assert main(["analyze", "3-PRS", "--config", "home", "--restarts=-1"]) == 2
    assert capsys.readouterr().err == (
        "pinmob: error: the number of random restarts (--restarts) must be at least 0, got -1\n"
    )
    assert main(["analyze", "3-PRS", "--config", "hme"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pinmob: error: no configuration 'hme' in '3-PRS' (did you mean 'home'?)")
