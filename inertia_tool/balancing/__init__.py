"""Balancing a rigid rotor on a shaft (Chapter 4, "Rigid Body Motion", §4.3.2, "Tire balancing"; ISO 21940)."""

from .drilling import DrilledHole
from .rotor import ISO_GRADES, BalanceReport, Correction, balance, balance_grade, permissible_unbalance

__all__ = ["balance", "BalanceReport", "Correction", "DrilledHole", "ISO_GRADES", "balance_grade",
           "permissible_unbalance"]
