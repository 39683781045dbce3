-- archgram schema 12: stable segment ids in a stored segmentation.
--
-- ROI refinement and template marking leave every segment that keeps a point its id, give
-- new segments ids after every id there was, and leave the id of a segment that lost all its
-- points unused (core/points/segment_cloud.h), so a segmentation's planes are no longer its
-- first ids. kinds holds the kind of each id, one byte per id below `segments` (0 plane,
-- 1 cluster, 2 element; an id no point has is unused, its byte what it was). A segmentation
-- stored before has kinds NULL and is read as before: the ids below `planes` are planes, the
-- rest clusters. From this schema on `planes` counts the planes that have points.
ALTER TABLE pointcloud_segmentations ADD COLUMN kinds BLOB
    CHECK (kinds IS NULL OR length(kinds) = segments);
