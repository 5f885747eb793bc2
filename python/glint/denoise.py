"""Locally-guided denoising (paper 2): a per-pixel noise level turned into a guidance map, and
guided Deep Image Prior / Self2Self (or plain DIP, S2S, OpenCV NLM) steered by it."""

from ._glint.denoise import noise_map, run

__all__ = ["noise_map", "run"]
