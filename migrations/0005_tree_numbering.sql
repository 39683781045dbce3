-- archgram schema 5: the numbering of a stored split tree. 1: read off the grammar's
-- derivation (schemas 2 to 4); 2: the node indices of the model's edit model, the ids edit ops
-- and previews name (server/app/model_tree.h). The service rebuilds a tree of numbering 1 from
-- the model's mesh the first time it needs it.
ALTER TABLE grammars ADD COLUMN tree_numbering INTEGER NOT NULL DEFAULT 1;
ALTER TABLE model_states ADD COLUMN tree_numbering INTEGER NOT NULL DEFAULT 1;
