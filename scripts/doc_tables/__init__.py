"""The generators of the docs' tables that scripts/reproduce re-makes, a module per page
(each module's TABLES: the table's name in docs/ -> its generator, which takes `quick`
and returns the table's rows)."""
