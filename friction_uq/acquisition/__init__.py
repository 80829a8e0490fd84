"""From oscilloscope files to a test record: ``friction-uq import FILE... --setup SETUP.toml -o test.h5``.

* :mod:`.setup_file`: SETUP.toml, what the files hold and the apparatus they came from;
* :mod:`.delimited`: CSV / TSV / semicolon or whitespace exports (:mod:`.text_layout`: dialect and
  header found, not assumed);
* :mod:`.binary`: NI TDMS (:mod:`.tdms`, npTDMS), LeCroy .trc (lecroyparser), Tektronix / Rigol /
  Keysight / Siglent / Yokogawa waveform files (RigolWFM);
* :mod:`.timebase`: each channel's start and sample interval, and where they came from;
* :mod:`.assemble`: one time base, units and signs, the record written, read back and checked;
* :mod:`.sanity`: gauges whose sign or scale contradicts the others, named with the evidence;
* :mod:`.template`: the commented SETUP.toml of the paper's set-up.

docs/import.md walks a lab through it.
"""

from .assemble import ImportOutcome, describe, import_scope_files
from .setup_file import Setup, load_setup, parse_setup
from .template import TEMPLATE

__all__ = ["TEMPLATE", "ImportOutcome", "Setup", "describe", "import_scope_files", "load_setup", "parse_setup"]
