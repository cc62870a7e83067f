"""Designing the inside of a part (placeholder, filled below)."""
