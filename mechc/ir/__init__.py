"""The data that flows between the stages: specs, expressions, netlists, mechanisms.

Plain types and their semantics only; no stage logic lives here (the stages are in
``mechc.passes``)."""
