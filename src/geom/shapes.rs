//! Shapes as points: axis-aligned rectangles cut into grids, and boxes made of them.
