"""Report writers: turn result objects into text, JSON-ready dicts and other formats.  Formatting only."""
