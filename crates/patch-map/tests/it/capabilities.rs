//! The backend × capability table of the crate docs, pinned.
//!
//! `positive_table` fails to *compile* if a backend loses a capability it should have;
//! `full_table` also checks, at run time with the autoref trick, that the capabilities a
//! backend should *not* have (the point-cloud map's, thesis §5.4.2) are absent, so a planner
//! needing them cannot be instantiated with it.

use patch_core::{
    Counted, FromPatches, LineStep, PatchMap, PatchMapMut, ProximityQuery, SpecificStepIntersector,
    UnspecificStepIntersector,
};
#[cfg(feature = "rapier")]
use patch_map::RapierMap;
use patch_map::{AnyMap, BBox6dMap, MapFile, MemoryUsage, PointCloudMap, PolygonMap, TrimeshMap};

fn assert_patch_map<T: PatchMap>() {}
fn assert_patch_map_mut<T: PatchMapMut>() {}
fn assert_from_patches<T: FromPatches>() {}
fn assert_proximity<T: ProximityQuery>() {}
fn assert_line_unspecific<T: UnspecificStepIntersector<LineStep>>() {}
fn assert_line_specific<T: SpecificStepIntersector<LineStep>>() {}
fn assert_capsule_unspecific<T: UnspecificStepIntersector>() {}
fn assert_capsule_specific<T: SpecificStepIntersector>() {}
fn assert_map_file<T: MapFile>() {}
fn assert_memory_usage<T: MemoryUsage>() {}
fn assert_send_sync<T: Send + Sync>() {}

/// Every capability of a full patch map.
fn assert_full<T>()
where
    T: PatchMap
        + PatchMapMut
        + FromPatches
        + ProximityQuery
        + SpecificStepIntersector<LineStep>
        + SpecificStepIntersector,
{
    assert_patch_map::<T>();
    assert_patch_map_mut::<T>();
    assert_from_patches::<T>();
    assert_proximity::<T>();
    assert_line_unspecific::<T>();
    assert_line_specific::<T>();
    assert_capsule_unspecific::<T>();
    assert_capsule_specific::<T>();
}

#[test]
fn positive_table() {
    // PolygonMap: everything.
    assert_full::<PolygonMap>();
    assert_map_file::<PolygonMap>();
    assert_memory_usage::<PolygonMap>();
    assert_send_sync::<PolygonMap>();

    // BBox6dMap: everything.
    assert_full::<BBox6dMap>();
    assert_map_file::<BBox6dMap>();
    assert_memory_usage::<BBox6dMap>();
    assert_send_sync::<BBox6dMap>();

    // PointCloudMap: the unspecific step queries only (thesis §5.4.2).
    assert_line_unspecific::<PointCloudMap>();
    assert_capsule_unspecific::<PointCloudMap>();
    assert_map_file::<PointCloudMap>();
    assert_memory_usage::<PointCloudMap>();
    assert_send_sync::<PointCloudMap>();

    // Any loaded map answers the unspecific queries.
    assert_line_unspecific::<AnyMap>();
    assert_capsule_unspecific::<AnyMap>();

    // Adaptors forward every capability.
    assert_full::<Counted<PolygonMap>>();
    assert_full::<Counted<BBox6dMap>>();
    assert_capsule_unspecific::<Counted<PointCloudMap>>();
    assert_proximity::<&BBox6dMap>();
    assert_capsule_specific::<&PolygonMap>();

    // TrimeshMap and RapierMap: everything.
    assert_full::<TrimeshMap>();
    assert_map_file::<TrimeshMap>();
    assert_memory_usage::<TrimeshMap>();
    assert_send_sync::<TrimeshMap>();
    #[cfg(feature = "rapier")]
    {
        assert_full::<RapierMap>();
        assert_map_file::<RapierMap>();
        assert_memory_usage::<RapierMap>();
    }
}

/// `implements!(T: Trait)`: whether the concrete type `T` implements `Trait`, as a `bool`
/// (autoref specialisation: the by-value candidate exists only when the bound holds).
macro_rules! implements {
    ($t:ty : $($bound:tt)+) => {{
        struct Probe<T: ?Sized>(std::marker::PhantomData<T>);
        #[allow(dead_code)] // one of `Yes` and `No` is unused in every expansion
        trait Yes {
            fn get(&self) -> bool {
                true
            }
        }
        impl<T: ?Sized + $($bound)+> Yes for Probe<T> {}
        #[allow(dead_code)]
        trait No {
            fn get(&self) -> bool {
                false
            }
        }
        impl<T: ?Sized> No for &Probe<T> {}
        (&Probe::<$t>(std::marker::PhantomData)).get()
    }};
}

/// One row: map, add, from patches, proximity, line unspecific/specific, capsule
/// unspecific/specific, map file, memory usage.
macro_rules! row {
    ($t:ty) => {
        [
            implements!($t: PatchMap),
            implements!($t: PatchMapMut),
            implements!($t: FromPatches),
            implements!($t: ProximityQuery),
            implements!($t: UnspecificStepIntersector<LineStep>),
            implements!($t: SpecificStepIntersector<LineStep>),
            implements!($t: UnspecificStepIntersector),
            implements!($t: SpecificStepIntersector),
            implements!($t: MapFile),
            implements!($t: MemoryUsage),
        ]
    };
}

#[test]
fn full_table() {
    const ALL: [bool; 10] = [true; 10];
    assert_eq!(row!(PolygonMap), ALL);
    assert_eq!(row!(BBox6dMap), ALL);
    assert_eq!(
        row!(PointCloudMap),
        [false, false, false, false, true, false, true, false, true, true],
        "the point-cloud map has the unspecific step queries only"
    );
    // The probe itself: a negative answer for a type that certainly lacks the trait.
    assert!(!implements!(u8: PatchMap));
    // TrimeshMap and RapierMap: everything.
    assert_full::<TrimeshMap>();
    assert_map_file::<TrimeshMap>();
    assert_memory_usage::<TrimeshMap>();
    assert_send_sync::<TrimeshMap>();
    #[cfg(feature = "rapier")]
    {
        assert_full::<RapierMap>();
        assert_map_file::<RapierMap>();
        assert_memory_usage::<RapierMap>();
    }
}
