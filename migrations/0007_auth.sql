-- archgram schema: accounts, API tokens and per-model roles.
--
-- An account's role says what it may do outside any one model: 'admin' (everything, every
-- model, managing accounts), 'editor' (creating models, writing the shared parts library),
-- 'viewer' (reading what is shared with it). Its role on a model is a row of model_members;
-- the account that made a model owns it.

CREATE TABLE users (
    id          INTEGER PRIMARY KEY,
    name        TEXT    NOT NULL UNIQUE CHECK (length(name) BETWEEN 1 AND 64),
    role        TEXT    NOT NULL DEFAULT 'editor' CHECK (role IN ('admin', 'editor', 'viewer')),
    created_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);

-- API tokens are shown once and kept only as a BLAKE2b-256 hash. `lookup` (the hash's first
-- 8 bytes) finds the row; the whole hash is then compared in constant time.
CREATE TABLE tokens (
    id          INTEGER PRIMARY KEY,
    user_id     INTEGER NOT NULL REFERENCES users(id) ON DELETE CASCADE,
    lookup      INTEGER NOT NULL UNIQUE,
    hash        BLOB    NOT NULL CHECK (length(hash) = 32),
    label       TEXT    NOT NULL DEFAULT '' CHECK (length(label) <= 100),
    created_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);
CREATE INDEX tokens_user ON tokens (user_id);

CREATE TABLE model_members (
    model_id    INTEGER NOT NULL REFERENCES models(id) ON DELETE CASCADE,
    user_id     INTEGER NOT NULL REFERENCES users(id) ON DELETE CASCADE,
    role        TEXT    NOT NULL CHECK (role IN ('owner', 'editor', 'viewer')),
    PRIMARY KEY (model_id, user_id)
) WITHOUT ROWID;
CREATE INDEX model_members_user ON model_members (user_id, model_id);

-- Readable by every account (the demo content is).
ALTER TABLE models ADD COLUMN public_read INTEGER NOT NULL DEFAULT 0 CHECK (public_read IN (0, 1));

-- Who asked for a job: they may read and cancel it, and own the model it makes. NULL: the
-- server itself (demo content).
ALTER TABLE jobs ADD COLUMN user_id INTEGER REFERENCES users(id) ON DELETE SET NULL;
