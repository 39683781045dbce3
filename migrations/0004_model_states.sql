-- archgram schema 4: the state of model versions, so undo, redo and restoring an old version
-- can bring back a version's mesh, grammar and split tree. A row is written for the version
-- before and after every structural edit and restore; a version without a row has the state
-- of the newest row before it when only rename and note ops lie between them.

CREATE TABLE model_states (
    model_id    INTEGER NOT NULL REFERENCES models(id) ON DELETE CASCADE,
    version     INTEGER NOT NULL CHECK (version >= 1),
    mesh_blob   INTEGER NOT NULL,                -- kept alive while a row names it
    stats       TEXT    NOT NULL DEFAULT '{}',   -- models.stats of that version
    grammar     TEXT,                            -- NULL when the version had no grammar
    tree        TEXT,
    summary     TEXT,
    PRIMARY KEY (model_id, version)
) WITHOUT ROWID;
CREATE INDEX model_states_blob ON model_states (mesh_blob);

-- A replaced mesh file stays while a kept state names it.
DROP TRIGGER models_replace_mesh;
CREATE TRIGGER models_replace_mesh AFTER UPDATE OF mesh_blob ON models
WHEN OLD.mesh_blob IS NOT NEW.mesh_blob BEGIN
    DELETE FROM blobs WHERE id = OLD.mesh_blob AND OLD.mesh_blob IS NOT NEW.source_blob
        AND NOT EXISTS (SELECT 1 FROM model_states WHERE mesh_blob = OLD.mesh_blob);
END;

-- A deleted model's mesh file stays while a kept state names it; the states go with the model
-- and take their files with them.
DROP TRIGGER models_delete_blobs;
CREATE TRIGGER models_delete_blobs AFTER DELETE ON models BEGIN
    DELETE FROM blobs WHERE id = OLD.source_blob;
    DELETE FROM blobs WHERE id = OLD.mesh_blob
        AND NOT EXISTS (SELECT 1 FROM model_states WHERE mesh_blob = OLD.mesh_blob);
END;
CREATE TRIGGER model_states_delete_blob AFTER DELETE ON model_states BEGIN
    DELETE FROM blobs WHERE id = OLD.mesh_blob
        AND NOT EXISTS (SELECT 1 FROM model_states WHERE mesh_blob = OLD.mesh_blob)
        AND NOT EXISTS (SELECT 1 FROM models WHERE mesh_blob = OLD.mesh_blob
                                                OR source_blob = OLD.mesh_blob);
END;
