-- archgram schema 1: models with versions, stored files, jobs and the op log.
-- Times are UTC ISO-8601 text with milliseconds.

CREATE TABLE blobs (
    id          INTEGER PRIMARY KEY,
    media_type  TEXT    NOT NULL,
    bytes       INTEGER NOT NULL CHECK (bytes >= 0),
    data        BLOB    NOT NULL
);

CREATE TABLE models (
    id          INTEGER PRIMARY KEY,
    name        TEXT    NOT NULL CHECK (length(name) BETWEEN 1 AND 200),
    kind        TEXT    NOT NULL DEFAULT 'mesh',
    version     INTEGER NOT NULL DEFAULT 1 CHECK (version >= 1),
    source_blob INTEGER REFERENCES blobs(id),
    source_format TEXT,
    mesh_blob   INTEGER NOT NULL REFERENCES blobs(id),
    stats       TEXT    NOT NULL DEFAULT '{}',   -- JSON summary of the current geometry
    created_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    updated_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);

-- The blobs a model owns go with it.
CREATE TRIGGER models_delete_blobs AFTER DELETE ON models BEGIN
    DELETE FROM blobs WHERE id IN (OLD.source_blob, OLD.mesh_blob);
END;

CREATE TABLE jobs (
    id          INTEGER PRIMARY KEY,
    kind        TEXT    NOT NULL,
    status      TEXT    NOT NULL DEFAULT 'queued'
                CHECK (status IN ('queued', 'running', 'succeeded', 'failed', 'cancelled')),
    progress    REAL    NOT NULL DEFAULT 0 CHECK (progress BETWEEN 0 AND 1),
    stage       TEXT,
    params      TEXT    NOT NULL DEFAULT '{}',   -- JSON
    result      TEXT,                            -- JSON, when succeeded
    error       TEXT,                            -- problem JSON, when failed or cancelled
    model_id    INTEGER REFERENCES models(id) ON DELETE SET NULL,
    created_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    updated_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);

-- One row per model version after the first: the op that made it.
CREATE TABLE ops (
    model_id    INTEGER NOT NULL REFERENCES models(id) ON DELETE CASCADE,
    version     INTEGER NOT NULL,
    author      TEXT    NOT NULL,
    cid         TEXT    NOT NULL,
    kind        TEXT    NOT NULL,
    body        TEXT    NOT NULL,                -- the op as JSON
    at          TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    PRIMARY KEY (model_id, version)
) WITHOUT ROWID;

-- A client id is used once per author and model: retries are answered, not re-applied.
CREATE UNIQUE INDEX ops_client_id ON ops (model_id, author, cid);
