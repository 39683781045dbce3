-- archgram schema: point clouds. A model of kind 'pointcloud' keeps its points here — their
-- count, local origin (offset) and scale, the list of their properties, and the columns of
-- their values (positions, normals, a level-of-detail order, every property) in chunks of
-- chunk_points points, so that no stored value comes near SQLite's blob limit and a reader
-- loads only the columns it serves. Segmentations (a segment, label and piece per point) are
-- kept per version that made one, so undo and restore bring a version's segmentation back;
-- the model's current one is pointclouds.segmentation. Everything goes with its model.

CREATE TABLE pointcloud_segmentations (
    id          INTEGER PRIMARY KEY,
    model_id    INTEGER NOT NULL REFERENCES models(id) ON DELETE CASCADE,
    version     INTEGER NOT NULL CHECK (version >= 1),  -- the model version that made it
    segments    INTEGER NOT NULL CHECK (segments >= 0),
    planes      INTEGER NOT NULL CHECK (planes BETWEEN 0 AND segments),  -- ids below are planes
    pieces      INTEGER NOT NULL CHECK (pieces >= 0),
    labels      INTEGER NOT NULL CHECK (labels >= 0),
    spacing     REAL    NOT NULL,                        -- metres, the label rule's slack
    id_width    INTEGER NOT NULL CHECK (id_width IN (1, 2, 4)),
    summary     TEXT    NOT NULL DEFAULT '{}'            -- JSON: counts, thresholds, seconds
);
CREATE INDEX pointcloud_segmentations_model ON pointcloud_segmentations (model_id);

-- Chunk k holds points [k * chunk_points, ...): their segment ids, then their label ids, then
-- their piece ids, id_width bytes each (little-endian, -1 = none).
CREATE TABLE pointcloud_segmentation_chunks (
    segmentation_id INTEGER NOT NULL REFERENCES pointcloud_segmentations(id) ON DELETE CASCADE,
    chunk       INTEGER NOT NULL CHECK (chunk >= 0),
    data        BLOB    NOT NULL,
    PRIMARY KEY (segmentation_id, chunk)
);

CREATE TABLE pointclouds (
    model_id    INTEGER PRIMARY KEY REFERENCES models(id) ON DELETE CASCADE,
    points      INTEGER NOT NULL CHECK (points >= 0),
    chunk_points INTEGER NOT NULL CHECK (chunk_points > 0),
    offset_x    REAL    NOT NULL,
    offset_y    REAL    NOT NULL,
    offset_z    REAL    NOT NULL,
    scale_x     REAL    NOT NULL DEFAULT 0,                -- 0: unknown (not LAS)
    scale_y     REAL    NOT NULL DEFAULT 0,
    scale_z     REAL    NOT NULL DEFAULT 0,
    positions   TEXT    NOT NULL CHECK (positions IN ('i32', 'f32', 'f64')),  -- io/cloudblob.h
    normals     INTEGER NOT NULL DEFAULT 0 CHECK (normals IN (0, 1)),
    properties  TEXT    NOT NULL DEFAULT '[]',             -- JSON [{"name", "type"}], in order
    segmentation INTEGER REFERENCES pointcloud_segmentations(id) ON DELETE SET NULL
);

-- Column 0: positions; 1: normals; 2: the level-of-detail order (core/points/lod.h: point
-- indices, every prefix an even subsample); 3 + i: property i.
CREATE TABLE pointcloud_columns (
    model_id    INTEGER NOT NULL REFERENCES pointclouds(model_id) ON DELETE CASCADE,
    col         INTEGER NOT NULL CHECK (col >= 0),
    chunk       INTEGER NOT NULL CHECK (chunk >= 0),
    data        BLOB    NOT NULL,
    PRIMARY KEY (model_id, col, chunk)
);

-- The segmentation of each kept model state (model_states, migration 0004), written and read
-- with it: NULL when that version was not segmented.
CREATE TABLE pointcloud_states (
    model_id    INTEGER NOT NULL REFERENCES models(id) ON DELETE CASCADE,
    version     INTEGER NOT NULL CHECK (version >= 1),
    segmentation INTEGER REFERENCES pointcloud_segmentations(id) ON DELETE SET NULL,
    PRIMARY KEY (model_id, version)
) WITHOUT ROWID;
CREATE INDEX pointcloud_states_segmentation ON pointcloud_states (segmentation);

-- A segmentation that is neither current nor kept by a state goes.
CREATE TRIGGER pointclouds_release_segmentation AFTER UPDATE OF segmentation ON pointclouds
WHEN OLD.segmentation IS NOT NULL AND OLD.segmentation IS NOT NEW.segmentation BEGIN
    DELETE FROM pointcloud_segmentations WHERE id = OLD.segmentation
        AND NOT EXISTS (SELECT 1 FROM pointcloud_states WHERE segmentation = OLD.segmentation);
END;
CREATE TRIGGER pointcloud_states_release_segmentation AFTER DELETE ON pointcloud_states
WHEN OLD.segmentation IS NOT NULL BEGIN
    DELETE FROM pointcloud_segmentations WHERE id = OLD.segmentation
        AND NOT EXISTS (SELECT 1 FROM pointcloud_states WHERE segmentation = OLD.segmentation)
        AND NOT EXISTS (SELECT 1 FROM pointclouds WHERE segmentation = OLD.segmentation);
END;
