-- archgram schema 8: what was built for each building of an extrusion. A building whose
-- description does not give a good building (a closed 2-manifold within reach of its
-- footprint) falls back; the row says to what, and how far a simplified footprint moved.
-- Rows from before keep NULL: built as described (or failed). Status 'not_watertight' is no
-- longer written: nothing that is not good is kept.

ALTER TABLE extrusion_buildings
    ADD COLUMN fallback TEXT CHECK (fallback IS NULL OR fallback IN ('simplified', 'flat', 'block'));
ALTER TABLE extrusion_buildings ADD COLUMN moved REAL;  -- metres, for 'simplified'
