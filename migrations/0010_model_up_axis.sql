-- archgram schema: how a model's up axis was decided when its file was imported.
--
-- JSON {"axis": "y"|"z", "decided": "request"|"file"|"content"|"convention", "evidence": {...}}
-- (schema/openapi.json, UpAxis); NULL for models that were not imported from a file (demo
-- buildings, extrusions) and for models imported before this migration.

ALTER TABLE models ADD COLUMN up_axis TEXT;
