//! vibroimpact
