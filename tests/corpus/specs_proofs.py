"""Hand transcriptions of the proof corpus files (see truth.py)."""

SPECS: dict = {}
