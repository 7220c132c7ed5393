//! Embree 3 (Intel's ray tracing kernels, the BVH Cycles traverses on CPUs) as an
//! `Accel` backend, loaded at run time from `libembree3.so.3` (Debian's `libembree3-3`,
//! 3.13.5), so one binary builds and runs without it and uses it when it is installed.
//!
//! Embree builds and traverses its own wide BVH over the leaves of our binary BVH,
//! registered as one user geometry: for each leaf a ray reaches, Embree calls back into
//! `Bvh::leaf`, which tests the leaf's triangles with our watertight test and tie rule and
//! shrinks the ray's far distance as our traversal does. Embree only decides which boxes
//! to enter, so every query returns exactly the hit `bvh2` and `bvh4` return and images
//! are bit-identical, provided Embree never culls a box our BVH would enter. Its box test
//! for user geometry is not the robust one (it computes `lo * (1/d) - o * (1/d)`, which
//! rounds differently from our `(lo - o) * (1/d)`, and culls a box entered exactly at the
//! best distance), so Embree is handed leaf boxes widened by 2^-20 of the scene's largest
//! coordinate and a far distance 2^-16 beyond the best hit: it only tests a few more
//! leaves, whose hits our test and tie rule then decide exactly. (Embree's own triangle test
//! gives other last bits of t and the barycentrics, and on shared edges may report the
//! other triangle: its native triangles could not match.)
//!
//! The C API is declared here (a dozen functions and four structs of
//! `embree3/rtcore*.h`, 3.13) rather than through a bindings crate, because those crates
//! link the library at build time, which the no-set-up default build cannot require.

use super::bvh::{Bvh, Hit, Watertight};
use super::math::*;
use std::ffi::{c_char, c_int, c_uint, c_void};
use std::sync::OnceLock;

/// The shared library Embree 3 installs (soname).
pub const LIBRARY: &str = "libembree3.so.3";

type Device = *mut c_void;
type Scene = *mut c_void;
type Geometry = *mut c_void;

const GEOMETRY_TYPE_USER: c_int = 120;
const SCENE_FLAG_ROBUST: c_int = 1 << 2;
const BUILD_QUALITY_HIGH: c_int = 2;
const INVALID_ID: c_uint = u32::MAX;
/// The largest box coordinate given to Embree (below its FLT_LARGE, 1.844e18).
const LARGE: f32 = 1e18;

/// `struct RTCIntersectContext` of a 3.13 build with `RTC_MAX_INSTANCE_LEVEL_COUNT` 1 and
/// no minimum width (Debian's `rtcore_config.h`).
#[repr(C)]
struct RtcContext {
    flags: c_int,
    filter: *const c_void,
    inst_id: [c_uint; 1],
}

#[repr(C, align(16))]
struct RtcRay {
    org: [f32; 3],
    tnear: f32,
    dir: [f32; 3],
    time: f32,
    tfar: f32,
    mask: c_uint,
    id: c_uint,
    flags: c_uint,
}

#[repr(C, align(16))]
struct RtcHit {
    ng: [f32; 3],
    u: f32,
    v: f32,
    prim_id: c_uint,
    geom_id: c_uint,
    inst_id: [c_uint; 1],
}

#[repr(C)]
struct RtcRayHit {
    ray: RtcRay,
    hit: RtcHit,
}

#[repr(C, align(16))]
struct RtcBounds {
    lower: [f32; 3],
    align0: f32,
    upper: [f32; 3],
    align1: f32,
}

#[repr(C)]
struct BoundsArgs {
    user: *mut c_void,
    prim_id: c_uint,
    time_step: c_uint,
    bounds: *mut RtcBounds,
}

/// `RTCIntersectFunctionNArguments` and `RTCOccludedFunctionNArguments` (same layout;
/// `ray` points at an `RTCRayHit` or an `RTCRay`, whose `tfar` is at the same offset).
#[repr(C)]
struct QueryArgs {
    valid: *mut c_int,
    user: *mut c_void,
    prim_id: c_uint,
    context: *mut RtcContext,
    ray: *mut RtcRay,
    n: c_uint,
    geom_id: c_uint,
}

type BoundsFn = unsafe extern "C" fn(*const BoundsArgs);
type QueryFn = unsafe extern "C" fn(*const QueryArgs);

/// The entry points used, resolved once from the library.
struct Api {
    new_device: unsafe extern "C" fn(*const c_char) -> Device,
    device_error: unsafe extern "C" fn(Device) -> c_int,
    new_scene: unsafe extern "C" fn(Device) -> Scene,
    release_scene: unsafe extern "C" fn(Scene),
    set_scene_flags: unsafe extern "C" fn(Scene, c_int),
    set_scene_build_quality: unsafe extern "C" fn(Scene, c_int),
    commit_scene: unsafe extern "C" fn(Scene),
    new_geometry: unsafe extern "C" fn(Device, c_int) -> Geometry,
    release_geometry: unsafe extern "C" fn(Geometry),
    commit_geometry: unsafe extern "C" fn(Geometry),
    attach_geometry: unsafe extern "C" fn(Scene, Geometry) -> c_uint,
    set_user_primitive_count: unsafe extern "C" fn(Geometry, c_uint),
    set_user_data: unsafe extern "C" fn(Geometry, *mut c_void),
    set_bounds_function: unsafe extern "C" fn(Geometry, BoundsFn, *mut c_void),
    set_intersect_function: unsafe extern "C" fn(Geometry, QueryFn),
    set_occluded_function: unsafe extern "C" fn(Geometry, QueryFn),
    intersect1: unsafe extern "C" fn(Scene, *mut RtcContext, *mut RtcRayHit),
    occluded1: unsafe extern "C" fn(Scene, *mut RtcContext, *mut RtcRay),
    /// The process's one device (Embree's thread pool and settings).
    device: Device,
    _lib: libloading::Library,
}

// The device is thread-safe by Embree's API contract; the rest are function pointers.
unsafe impl Send for Api {}
unsafe impl Sync for Api {}

fn load() -> Result<Api, String> {
    let why = |e: &dyn std::fmt::Display| {
        format!("Embree is not available: {LIBRARY} could not be loaded ({e}); install Embree 3 (Debian: apt-get install libembree3-3)")
    };
    // SAFETY: loading Embree runs only its static initialisers.
    let lib = unsafe { libloading::Library::new(LIBRARY) }.map_err(|e| why(&e))?;
    macro_rules! sym {
        ($name:literal) => {
            // SAFETY: the signature is the one `rtcore*.h` 3.13 declares for this name.
            *unsafe { lib.get($name) }.map_err(|e| why(&e))?
        };
    }
    let mut api = Api {
        new_device: sym!(b"rtcNewDevice\0"),
        device_error: sym!(b"rtcGetDeviceError\0"),
        new_scene: sym!(b"rtcNewScene\0"),
        release_scene: sym!(b"rtcReleaseScene\0"),
        set_scene_flags: sym!(b"rtcSetSceneFlags\0"),
        set_scene_build_quality: sym!(b"rtcSetSceneBuildQuality\0"),
        commit_scene: sym!(b"rtcCommitScene\0"),
        new_geometry: sym!(b"rtcNewGeometry\0"),
        release_geometry: sym!(b"rtcReleaseGeometry\0"),
        commit_geometry: sym!(b"rtcCommitGeometry\0"),
        attach_geometry: sym!(b"rtcAttachGeometry\0"),
        set_user_primitive_count: sym!(b"rtcSetGeometryUserPrimitiveCount\0"),
        set_user_data: sym!(b"rtcSetGeometryUserData\0"),
        set_bounds_function: sym!(b"rtcSetGeometryBoundsFunction\0"),
        set_intersect_function: sym!(b"rtcSetGeometryIntersectFunction\0"),
        set_occluded_function: sym!(b"rtcSetGeometryOccludedFunction\0"),
        intersect1: sym!(b"rtcIntersect1\0"),
        occluded1: sym!(b"rtcOccluded1\0"),
        device: std::ptr::null_mut(),
        _lib: lib,
    };
    // SAFETY: a null configuration string asks for Embree's defaults.
    api.device = unsafe { (api.new_device)(std::ptr::null()) };
    if api.device.is_null() {
        // SAFETY: a null device reads the error of the failed device creation.
        let code = unsafe { (api.device_error)(std::ptr::null_mut()) };
        return Err(format!(
            "Embree ({LIBRARY}) could not create a device: {}",
            error_name(code)
        ));
    }
    Ok(api)
}

fn error_name(code: c_int) -> &'static str {
    match code {
        0 => "no error",
        2 => "RTC_ERROR_INVALID_ARGUMENT",
        3 => "RTC_ERROR_INVALID_OPERATION",
        4 => "RTC_ERROR_OUT_OF_MEMORY",
        5 => "RTC_ERROR_UNSUPPORTED_CPU",
        6 => "RTC_ERROR_CANCELLED",
        _ => "RTC_ERROR_UNKNOWN",
    }
}

fn api() -> Result<&'static Api, String> {
    static API: OnceLock<Result<Api, String>> = OnceLock::new();
    API.get_or_init(load).as_ref().map_err(|e| e.clone())
}

/// Whether Embree can be used here (the library loads and a device starts); the error
/// names the library.
pub fn available() -> Result<(), String> {
    api().map(|_| ())
}

/// What the callbacks read: the triangles (our BVH, for its leaves and their test) and
/// each Embree primitive's leaf.
struct Leaves {
    bvh: Bvh,
    /// Per Embree primitive: (first triangle in leaf order, count, box).
    leaves: Vec<(u32, u32, V3, V3)>,
}

/// One query's state, passed to the callbacks as Embree's context (the context comes
/// first, so the pointer Embree hands back is this struct's).
#[repr(C)]
struct Query {
    rtc: RtcContext,
    wt: Watertight,
    org: V3,
    tmin: f32,
    filter: bool,
    mask: u32,
    best: Option<Hit>,
    /// The best hit's distance (the ray's end until one is found): the exact value our
    /// test compares with; Embree's ray carries `widen_far` of it.
    tfar: f32,
}

/// The far distance Embree culls with: a little beyond ours (see the module doc).
#[inline(always)]
fn widen_far(t: f32) -> f32 {
    t + t.abs() * (1.0 / 65536.0)
}

/// An Embree scene over triangles: same hits as `Bvh` (see the module doc).
pub struct EmbreeAccel {
    api: &'static Api,
    scene: Scene,
    /// Boxed so the callbacks' user pointer stays put.
    data: Box<Leaves>,
}

// Embree scenes may be queried from many threads at once once committed.
unsafe impl Send for EmbreeAccel {}
unsafe impl Sync for EmbreeAccel {}

impl Drop for EmbreeAccel {
    fn drop(&mut self) {
        if !self.scene.is_null() {
            // SAFETY: the scene was made by this device and is no longer queried.
            unsafe { (self.api.release_scene)(self.scene) };
        }
    }
}

unsafe extern "C" fn bounds_cb(args: *const BoundsArgs) {
    // SAFETY: Embree passes the user pointer set in `build_masked` and a primitive id
    // below the count given there.
    unsafe {
        let a = &*args;
        let data = &*(a.user as *const Leaves);
        let (_, _, lo, hi) = data.leaves[a.prim_id as usize];
        *a.bounds = RtcBounds {
            lower: lo,
            align0: 0.0,
            upper: hi,
            align1: 0.0,
        };
    }
}

/// Tests primitive `args.prim_id`'s triangles; the nearest query (`ANY` false) keeps the
/// best hit in the `Query` and shrinks the ray's `tfar` to it, the occlusion query marks
/// the ray occluded (`tfar` = -inf, Embree's convention) at the first hit.
unsafe extern "C" fn query_cb<const ANY: bool>(args: *const QueryArgs) {
    // SAFETY: single-ray queries (`n` is 1) from `EmbreeAccel::traverse`, whose context
    // is a `Query` and whose user pointer is the scene's `Leaves`.
    unsafe {
        let a = &*args;
        if *a.valid == 0 {
            return;
        }
        let data = &*(a.user as *const Leaves);
        let q = &mut *(a.context as *mut Query);
        let ray = &mut *a.ray;
        let (start, count, _, _) = data.leaves[a.prim_id as usize];
        let found = data.bvh.leaf::<ANY>(
            start..start + count,
            &q.wt,
            q.org,
            q.tmin,
            &mut q.tfar,
            &mut q.best,
            q.filter,
            q.mask,
        );
        if found {
            ray.tfar = if ANY {
                f32::NEG_INFINITY
            } else {
                widen_far(q.tfar)
            };
        }
    }
}

impl EmbreeAccel {
    /// The Embree scene over `tris` with visibility `masks` (as `Bvh::build_masked`).
    pub fn build_masked(tris: &[[V3; 3]], masks: &[u32]) -> Result<EmbreeAccel, String> {
        let api = api()?;
        let bvh = Bvh::build_masked(tris, masks);
        // The largest finite coordinate: a triangle with an infinite or NaN vertex (which
        // our test never hits) must not make every box infinite.
        let finite = |x: f32| if x.is_finite() { x.abs() } else { 0.0 };
        let extent = bvh
            .tree
            .nodes
            .iter()
            .filter(|n| n.count > 0)
            .fold(0.0f32, |m, n| {
                (0..3).fold(m, |m, a| m.max(finite(n.min[a])).max(finite(n.max[a])))
            });
        let pad = extent * (1.0 / 1048576.0) + f32::MIN_POSITIVE;
        // Embree drops a primitive whose box reaches beyond its FLT_LARGE (1.844e18) or
        // is not finite; such a leaf (which may hold other, finite triangles) is clamped
        // to +-1e18 instead (so only hits farther than that could differ).
        let leaves: Vec<(u32, u32, V3, V3)> = bvh
            .tree
            .nodes
            .iter()
            .filter(|n| n.count > 0)
            .map(|n| {
                let lo = n.min.map(|x| (x - pad).max(-LARGE));
                let hi = n.max.map(|x| (x + pad).min(LARGE));
                (n.start, n.count, lo, hi)
            })
            .collect();
        let data = Box::new(Leaves { bvh, leaves });
        if data.leaves.is_empty() || tris.is_empty() {
            return Ok(EmbreeAccel {
                api,
                scene: std::ptr::null_mut(),
                data,
            });
        }
        // SAFETY: calls in the order Embree's API documents, on objects of this device;
        // `data` outlives the scene (released first in `drop`).
        unsafe {
            let d = api.device;
            let scene = (api.new_scene)(d);
            if scene.is_null() {
                return Err(device_error(api, "rtcNewScene"));
            }
            let accel = EmbreeAccel { api, scene, data };
            (api.set_scene_flags)(scene, SCENE_FLAG_ROBUST);
            (api.set_scene_build_quality)(scene, BUILD_QUALITY_HIGH);
            let g = (api.new_geometry)(d, GEOMETRY_TYPE_USER);
            if g.is_null() {
                return Err(device_error(api, "rtcNewGeometry"));
            }
            let user = &*accel.data as *const Leaves as *mut c_void;
            (api.set_user_primitive_count)(g, accel.data.leaves.len() as c_uint);
            (api.set_user_data)(g, user);
            (api.set_bounds_function)(g, bounds_cb, std::ptr::null_mut());
            (api.set_intersect_function)(g, query_cb::<false>);
            (api.set_occluded_function)(g, query_cb::<true>);
            (api.commit_geometry)(g);
            (api.attach_geometry)(scene, g);
            (api.release_geometry)(g);
            (api.commit_scene)(scene);
            let code = (api.device_error)(d);
            if code != 0 {
                return Err(format!(
                    "Embree ({LIBRARY}) could not build the scene's BVH ({} triangles): {}",
                    tris.len(),
                    error_name(code)
                ));
            }
            Ok(accel)
        }
    }

    #[inline(always)]
    fn traverse<const ANY: bool>(
        &self,
        org: V3,
        dir: V3,
        tmin: f32,
        tmax: f32,
        mask: u32,
    ) -> Option<Hit> {
        if self.scene.is_null() {
            return None;
        }
        let mut q = Query {
            rtc: RtcContext {
                flags: 0,
                filter: std::ptr::null(),
                inst_id: [INVALID_ID],
            },
            wt: Watertight::new(dir),
            org,
            tmin,
            filter: self.data.bvh.filters(mask),
            mask,
            best: None,
            tfar: tmax,
        };
        let ray = RtcRay {
            org,
            tnear: tmin - tmin.abs() * (1.0 / 65536.0),
            dir,
            time: 0.0,
            tfar: widen_far(tmax),
            mask: u32::MAX,
            id: 0,
            flags: 0,
        };
        // SAFETY: a committed scene; `q` starts with the context Embree reads and is what
        // the callbacks cast it back to.
        unsafe {
            let ctx = &mut q as *mut Query as *mut RtcContext;
            if ANY {
                let mut ray = ray;
                (self.api.occluded1)(self.scene, ctx, &mut ray);
            } else {
                let mut rh = RtcRayHit {
                    ray,
                    hit: RtcHit {
                        ng: [0.0; 3],
                        u: 0.0,
                        v: 0.0,
                        prim_id: INVALID_ID,
                        geom_id: INVALID_ID,
                        inst_id: [INVALID_ID],
                    },
                };
                (self.api.intersect1)(self.scene, ctx, &mut rh);
            }
        }
        q.best
    }
}

fn device_error(api: &Api, what: &str) -> String {
    // SAFETY: the process's device.
    let code = unsafe { (api.device_error)(api.device) };
    format!("Embree ({LIBRARY}): {what} failed: {}", error_name(code))
}

super::bvh::accel_by_traverse!(EmbreeAccel);
