-- archgram schema 11: model_states as a rowid table, and an edit's tree written once.
--
-- A state row holds a version's grammar and split tree (megabytes for a large building). In
-- a WITHOUT ROWID table the rows are the primary key's b-tree, and SQLite reads a key that
-- spills into overflow pages whole to compare it: every look-up of a version (does it have a
-- kept state?) read the large rows it passed, milliseconds per edit. As a rowid table, the
-- key (model_id, version) is a small index of its own and the rows stay where they are.
--
-- From this schema on, a grammars row whose tree is '' has its tree in the model_states row
-- of its version (server/store/grammars.h): an edit stores its tree once, as the kept state
-- of the version it makes, instead of twice.
CREATE TABLE model_states_copy AS SELECT * FROM model_states;
DROP TABLE model_states;

CREATE TABLE model_states (
    model_id    INTEGER NOT NULL REFERENCES models(id) ON DELETE CASCADE,
    version     INTEGER NOT NULL CHECK (version >= 1),
    mesh_blob   INTEGER NOT NULL,                -- kept alive while a row names it
    stats       TEXT    NOT NULL DEFAULT '{}',   -- models.stats of that version
    grammar     TEXT,                            -- NULL when the version had no grammar
    tree        TEXT,
    summary     TEXT,
    tree_numbering INTEGER NOT NULL DEFAULT 1,
    PRIMARY KEY (model_id, version)
);
INSERT INTO model_states (model_id, version, mesh_blob, stats, grammar, tree, summary,
                          tree_numbering)
    SELECT model_id, version, mesh_blob, stats, grammar, tree, summary, tree_numbering
    FROM model_states_copy;
DROP TABLE model_states_copy;
CREATE INDEX model_states_blob ON model_states (mesh_blob);

-- as in schema 4: a state's mesh file goes with its last reference
CREATE TRIGGER model_states_delete_blob AFTER DELETE ON model_states BEGIN
    DELETE FROM blobs WHERE id = OLD.mesh_blob
        AND NOT EXISTS (SELECT 1 FROM model_states WHERE mesh_blob = OLD.mesh_blob)
        AND NOT EXISTS (SELECT 1 FROM models WHERE mesh_blob = OLD.mesh_blob
                                                OR source_blob = OLD.mesh_blob);
END;
