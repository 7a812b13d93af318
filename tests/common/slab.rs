//! The signature `slab_voids` and `slab_voids_reference` share, for tests/estimate3d_fast.rs
//! and examples/estimate3d_profile.rs to hand either to the same code.

use dropslice::Settings;
use dropslice::analysis::{Grid3, HeightMap};
use dropslice::base::geom::Shapes;

/// [`dropslice::analysis::slab_voids`] or [`dropslice::analysis::slab_voids_reference`]: a
/// slab's (volume, void volume) from its region, the grid and the height maps below, of and
/// above its layer.
pub type SlabFn = fn(
    &Shapes,
    &Grid3,
    Option<&HeightMap>,
    &HeightMap,
    Option<&HeightMap>,
    &Settings,
) -> (f64, f64);
