"""Closing the loop: from a fit's residual to the effect the model lacks (docs/closing-the-loop.md).

A layer between ``io`` (above: files) and ``fit`` (below: the fit it starts from): it reads and writes no file.
"""
