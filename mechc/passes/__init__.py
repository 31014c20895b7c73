"""The compiler stages, one per file: each a plain function from one ``mechc.ir`` type to
the next (minimise, map, amplify, place, assemble, check). ``mechc.pipeline`` runs them."""
