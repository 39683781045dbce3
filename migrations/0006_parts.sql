-- archgram schema 6: the parts library. A part is a piece of a proceduralized building kept as
-- a grammar of its own (schema/part_bundle.md), with versions: an update makes a new version,
-- and compositions name the version they used. A part does not depend on the model it was
-- saved from: provenance is recorded, not referenced, so deleting the model leaves the part
-- whole. Terminal geometry is kept once per content (SHA-256) for the whole library.

-- AUTOINCREMENT: a deleted part's id is never given again, so an op log naming a part never
-- comes to name another one.
CREATE TABLE parts (
    id          INTEGER PRIMARY KEY AUTOINCREMENT,
    name        TEXT    NOT NULL CHECK (length(name) BETWEEN 1 AND 200),
    description TEXT    NOT NULL DEFAULT '',
    version     INTEGER NOT NULL CHECK (version >= 1),  -- the newest version
    created_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    updated_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);

-- The newest version's tags, for the tag filter.
CREATE TABLE part_tags (
    part_id     INTEGER NOT NULL REFERENCES parts(id) ON DELETE CASCADE,
    tag         TEXT    NOT NULL CHECK (length(tag) BETWEEN 1 AND 200),
    position    INTEGER NOT NULL,
    PRIMARY KEY (part_id, tag)
) WITHOUT ROWID;
CREATE INDEX part_tags_by_tag ON part_tags (tag, part_id);

-- Every version as it was saved: its entry of a part bundle (JSON: metadata, grammar with
-- terminals named by hash, proportions, attributes), provenance and a thumbnail.
CREATE TABLE part_versions (
    part_id        INTEGER NOT NULL REFERENCES parts(id) ON DELETE CASCADE,
    version        INTEGER NOT NULL CHECK (version >= 1),
    entry          TEXT    NOT NULL,               -- JSON, schema/part_bundle.md "parts[i]"
    source_model   INTEGER,                        -- the model's id then; no reference
    source_name    TEXT,
    source_version INTEGER NOT NULL DEFAULT 0,
    source_node    INTEGER NOT NULL DEFAULT -1,
    thumbnail      BLOB    NOT NULL,               -- PNG
    stats          TEXT    NOT NULL DEFAULT '{}',  -- JSON: nodes, rules, terminals, triangles, size
    created_at     TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    PRIMARY KEY (part_id, version)
) WITHOUT ROWID;

-- Terminal OBJ texts by the SHA-256 of their content, shared by every version that uses one.
CREATE TABLE part_terminals (
    sha256      TEXT    PRIMARY KEY CHECK (length(sha256) = 64),
    obj         TEXT    NOT NULL
) WITHOUT ROWID;

CREATE TABLE part_version_terminals (
    part_id     INTEGER NOT NULL,
    version     INTEGER NOT NULL,
    sha256      TEXT    NOT NULL REFERENCES part_terminals(sha256),
    PRIMARY KEY (part_id, version, sha256),
    FOREIGN KEY (part_id, version) REFERENCES part_versions(part_id, version) ON DELETE CASCADE
) WITHOUT ROWID;
CREATE INDEX part_version_terminals_by_hash ON part_version_terminals (sha256);

-- A terminal no version uses any more goes.
CREATE TRIGGER part_version_terminals_release AFTER DELETE ON part_version_terminals BEGIN
    DELETE FROM part_terminals WHERE sha256 = OLD.sha256
        AND NOT EXISTS (SELECT 1 FROM part_version_terminals WHERE sha256 = OLD.sha256);
END;

-- Full-text search over the newest version's name, tags and description (rowid = parts.id),
-- written by store/parts.c in the transaction that changes the part, dropped with the part.
CREATE VIRTUAL TABLE parts_search USING fts5(name, tags, description, tokenize = 'unicode61');
CREATE TRIGGER parts_delete_search AFTER DELETE ON parts BEGIN
    DELETE FROM parts_search WHERE rowid = OLD.id;
END;
