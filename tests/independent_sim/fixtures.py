"""Pytest fixtures serving the independent corpus, written once per test session.

Import the fixture functions into a test module (importing is what registers
them; their names end in ``_fixture``, the fixtures are named without it),
then ask for the fixtures by name::

    from independent_sim.fixtures import (  # noqa: F401 (registers the fixtures)
        heldout_case_files_fixture,
        independent_corpus_fixture,
    )

    def test_sweeps_found(independent_corpus):
        files = independent_corpus.files("heldout-px4-sweeps")  # CaseFiles: .log, .truth, .anemometer_csv
        ...

    def test_every_heldout_log(heldout_case_files):  # parametrised over HELDOUT_CASES
        ...

``heldout_case_files`` and ``tuning_case_files`` need ``independent_corpus``
imported too. Logs are generated on first request and kept under one session
temporary folder; a second request for the same case (and format) returns the
same files. :class:`Corpus` can also be used without pytest.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from independent_sim.catalogue import HELDOUT_CASES, TUNING_CASES, case_named
from independent_sim.corpus import CaseFiles, write_case
from independent_sim.scenario import LogFormat

__all__ = ["Corpus", "independent_corpus_fixture", "heldout_case_files_fixture", "tuning_case_files_fixture"]


class Corpus:
    """Cases of the catalogue written on demand into one folder, each once.

    Parameters
    ----------
    root : Path
        Folder to write into (created if missing).

    Examples
    --------
    >>> import tempfile
    >>> corpus = Corpus(Path(tempfile.mkdtemp()))
    >>> corpus.files("heldout-ap-hover") is corpus.files("heldout-ap-hover")
    True
    """

    def __init__(self, root: Path) -> None:
        self.root = Path(root)
        self._written: dict[tuple[str, LogFormat], CaseFiles] = {}

    def files(self, name: str, fmt: LogFormat | None = None) -> CaseFiles:
        """The files of case `name` in `fmt` (default: the case's own format), written on first use.

        Parameters
        ----------
        name : str
            A catalogue case name.
        fmt : {"ulog", "dataflash"}, optional
            Log format; another than the case's flies it with that autopilot's profile.

        Returns
        -------
        CaseFiles
        """
        case = case_named(name)
        key = (name, fmt or case.fmt)
        if key not in self._written:
            folder = self.root / f"{name}-{key[1]}"
            folder.mkdir(parents=True, exist_ok=True)
            self._written[key] = write_case(case, folder, key[1])
        return self._written[key]


@pytest.fixture(scope="session", name="independent_corpus")
def independent_corpus_fixture(tmp_path_factory: pytest.TempPathFactory) -> Corpus:
    """The corpus for this session; logs are written when first asked for."""
    return Corpus(tmp_path_factory.mktemp("independent-corpus"))


@pytest.fixture(scope="session", name="heldout_case_files", params=[case.name for case in HELDOUT_CASES])
def heldout_case_files_fixture(request: pytest.FixtureRequest, independent_corpus: Corpus) -> CaseFiles:
    """Each held-out case's files in turn (assert on these; never tune on them)."""
    return independent_corpus.files(request.param)


@pytest.fixture(scope="session", name="tuning_case_files", params=[case.name for case in TUNING_CASES])
def tuning_case_files_fixture(request: pytest.FixtureRequest, independent_corpus: Corpus) -> CaseFiles:
    """Each tuning case's files in turn (a detector may be tuned on these)."""
    return independent_corpus.files(request.param)
