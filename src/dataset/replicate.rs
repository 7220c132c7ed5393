//! `blendsynth replicate --dataset doi-23843904`: placeholder, filled below.
