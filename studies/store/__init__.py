"""The output folder and what is stored in it: atomic writers (`writers`, `xdmf_series`),
checked checkpoints and the quarantine of damaged files, the folder's lock and its
size estimate, and the resumable stores of `sweep` and `orbits`.  Below the drivers,
the presentation and the post-processing of studies/: it imports none of them."""
