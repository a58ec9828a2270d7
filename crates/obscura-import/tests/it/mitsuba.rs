//! Mitsuba 3 scenes (see the pbrt tests for the shape of these).
