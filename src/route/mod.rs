//! Trace routing: weighted A* on per-layer perimeter graphs.
