"""Analyses built on scenes and results: order spectra of dynamic runs (:mod:`.spectrum`)."""
