//! Exact optimum: maximum-weight maximum-cardinality matching on the dual graph ("Blossom-quad").
