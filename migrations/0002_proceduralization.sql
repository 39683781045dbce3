-- archgram schema 2: proceduralization. The split grammar that derives a model's mesh, its
-- split tree (JSON, as served by GET /api/v1/models/{id}/tree), a summary, and the terminal
-- geometry the grammar names. Everything goes with its model.

-- The grammar made by one model version (a proceduralize job or a grammar edit). It describes
-- the model while models.mesh_blob is still mesh_blob; only the newest row of a model is kept.
CREATE TABLE grammars (
    id          INTEGER PRIMARY KEY,
    model_id    INTEGER NOT NULL REFERENCES models(id) ON DELETE CASCADE,
    version     INTEGER NOT NULL CHECK (version >= 1),
    mesh_blob   INTEGER NOT NULL,
    text        TEXT    NOT NULL,
    tree        TEXT    NOT NULL,                -- JSON
    summary     TEXT    NOT NULL DEFAULT '{}',   -- JSON
    created_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    UNIQUE (model_id, version)
);

-- Terminal geometry by the path the grammar text uses ("terminals/<16 hex>.obj", named after
-- a hash of the OBJ text, so a path always means the same content).
CREATE TABLE terminals (
    model_id    INTEGER NOT NULL REFERENCES models(id) ON DELETE CASCADE,
    path        TEXT    NOT NULL,
    obj         TEXT    NOT NULL,
    PRIMARY KEY (model_id, path)
) WITHOUT ROWID;

-- A model whose mesh is replaced (proceduralization, grammar edits) drops the old mesh file.
CREATE TRIGGER models_replace_mesh AFTER UPDATE OF mesh_blob ON models
WHEN OLD.mesh_blob IS NOT NEW.mesh_blob BEGIN
    DELETE FROM blobs WHERE id = OLD.mesh_blob AND OLD.mesh_blob IS NOT NEW.source_blob;
END;
