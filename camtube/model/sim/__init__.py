"""Simulated measurements: the base model plus noise (:mod:`.synth`, ``camtube model synth``) and an
independent time-stepping truth simulator with hidden effects (:mod:`.truth`, used to test the diagnosis)."""
