"""Optimal experimental design for a calibration schedule (docs/planning.md).

A layer between ``diagnose`` and ``fit``: it uses the fit's model of the segment means for the information each
candidate segment carries, and the uncertainty layer's prediction of their noise; it reads no file.
"""
