-- archgram schema 3: procedural extrusions. A model of kind 'extrusion' keeps the building
-- descriptions (plan JSON, schema/plan.md) it was extruded from, one row per building, so a
-- plan or profile edit re-extrudes only the buildings it touches. Everything goes with its
-- model.

-- One row per extrusion model: how it was made.
CREATE TABLE extrusions (
    model_id    INTEGER PRIMARY KEY REFERENCES models(id) ON DELETE CASCADE,
    batch       INTEGER NOT NULL CHECK (batch IN (0, 1)),  -- 0: one plan uploaded as it is
    meta        TEXT    NOT NULL DEFAULT '{}'              -- JSON: format, style, origin, lonlat
);

-- The buildings in mesh order: building i's geometry is the i-th component of the model's
-- mesh among the buildings that have geometry.
CREATE TABLE extrusion_buildings (
    id          INTEGER PRIMARY KEY,
    model_id    INTEGER NOT NULL REFERENCES extrusions(model_id) ON DELETE CASCADE,
    building    INTEGER NOT NULL CHECK (building >= 0),
    footprint   TEXT    NOT NULL,                -- feature id, the mesh group's name
    plan        TEXT    NOT NULL,                -- building description JSON
    mesh        BLOB,                            -- this building alone (meshblob); NULL if failed
    triangles   INTEGER NOT NULL DEFAULT 0,
    status      TEXT    NOT NULL CHECK (status IN ('ok', 'not_watertight', 'failed')),
    reason      TEXT,                            -- why it failed or is not watertight
    UNIQUE (model_id, building)
);
