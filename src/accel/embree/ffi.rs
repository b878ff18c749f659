//! The part of Embree 3's C API (`rtcore.h`, 3.13) the `embree` structure calls, opened at run
//! time from the system library (`libembree3.so.3`, Debian's `libembree3-3`): the project builds
//! and runs without it, and only a build of this structure needs it, failing with an error that
//! says what to install.
//!
//! The layouts below are the header's for `RTC_MAX_INSTANCE_LEVEL_COUNT == 1` and
//! `RTC_MIN_WIDTH == 0`, the configuration Debian builds (`rtcore_config.h`); the version is
//! checked when the library is opened.

use std::ffi::{c_char, c_void, CStr};
use std::sync::OnceLock;

/// `RTCDevice`, `RTCScene`, `RTCGeometry`: opaque handles.
pub type Handle = *mut c_void;

/// `struct RTCRay`: origin, near end, direction, time, far end (the hit distance after a hit),
/// mask, id, flags.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub org: [f32; 3],
    pub tnear: f32,
    pub dir: [f32; 3],
    pub time: f32,
    pub tfar: f32,
    pub mask: u32,
    pub id: u32,
    pub flags: u32,
}

/// `struct RTCHit` with one instance level.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub ng: [f32; 3],
    pub u: f32,
    pub v: f32,
    pub prim_id: u32,
    pub geom_id: u32,
    pub inst_id: [u32; 1],
}

/// `struct RTCRayHit`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RayHit {
    pub ray: Ray,
    pub hit: Hit,
}

const _: () = assert!(std::mem::size_of::<Ray>() == 48 && std::mem::size_of::<Hit>() == 32);
const _: () = assert!(std::mem::size_of::<RayHit>() == 80);
const _: () = assert!(std::mem::size_of::<IntersectContext>() == 24 && std::mem::size_of::<FilterArguments>() == 48);

/// `struct RTCFilterFunctionNArguments`.
#[repr(C)]
pub struct FilterArguments {
    pub valid: *mut i32,
    pub geometry_user_ptr: *mut c_void,
    pub context: *mut IntersectContext,
    pub ray: *mut c_void,
    pub hit: *mut c_void,
    pub n: u32,
}

/// `RTCFilterFunctionN`.
pub type FilterFunction = unsafe extern "C" fn(*const FilterArguments);

/// `struct RTCIntersectContext` with one instance level: flags, the context's filter function
/// (called on every hit where the scene has `SCENE_FLAG_CONTEXT_FILTER_FUNCTION`), instance ids.
#[repr(C)]
pub struct IntersectContext {
    pub flags: u32,
    pub filter: Option<FilterFunction>,
    pub inst_id: [u32; 1],
}

impl IntersectContext {
    /// `rtcInitIntersectContext` with `filter`.
    pub fn new(filter: Option<FilterFunction>) -> IntersectContext {
        IntersectContext {
            flags: CONTEXT_FLAG_INCOHERENT,
            filter,
            inst_id: [INVALID_ID],
        }
    }
}

/// `RTC_INVALID_GEOMETRY_ID`: no hit.
pub const INVALID_ID: u32 = u32::MAX;
/// `RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT`.
pub const CONTEXT_FLAG_INCOHERENT: u32 = 0;
/// `RTC_GEOMETRY_TYPE_TRIANGLE`.
pub const GEOMETRY_TYPE_TRIANGLE: u32 = 0;
/// `RTC_BUFFER_TYPE_INDEX`, `RTC_BUFFER_TYPE_VERTEX`.
pub const BUFFER_TYPE_INDEX: u32 = 0;
pub const BUFFER_TYPE_VERTEX: u32 = 1;
/// `RTC_FORMAT_UINT3`, `RTC_FORMAT_FLOAT3`.
pub const FORMAT_UINT3: u32 = 0x5003;
pub const FORMAT_FLOAT3: u32 = 0x9003;
/// `RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION`.
pub const SCENE_FLAG_CONTEXT_FILTER_FUNCTION: u32 = 1 << 3;
/// `RTC_DEVICE_PROPERTY_VERSION`, `RTC_DEVICE_PROPERTY_BACKFACE_CULLING_ENABLED`,
/// `RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED`.
pub const DEVICE_PROPERTY_VERSION: u32 = 0;
pub const DEVICE_PROPERTY_BACKFACE_CULLING_ENABLED: u32 = 65;
pub const DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED: u32 = 66;

/// `RTCMemoryMonitorFunction`: bytes allocated (> 0) or freed (< 0); true lets it happen.
pub type MemoryMonitor = unsafe extern "C" fn(*mut c_void, isize, bool) -> bool;

/// The entry points, resolved once from the library, which stays loaded for the process.
pub struct Api {
    pub new_device: unsafe extern "C" fn(*const c_char) -> Handle,
    pub release_device: unsafe extern "C" fn(Handle),
    pub get_device_error: unsafe extern "C" fn(Handle) -> u32,
    pub get_device_property: unsafe extern "C" fn(Handle, u32) -> isize,
    pub set_device_memory_monitor: unsafe extern "C" fn(Handle, Option<MemoryMonitor>, *mut c_void),
    pub new_scene: unsafe extern "C" fn(Handle) -> Handle,
    pub release_scene: unsafe extern "C" fn(Handle),
    pub set_scene_flags: unsafe extern "C" fn(Handle, u32),
    pub set_scene_build_quality: unsafe extern "C" fn(Handle, u32),
    pub attach_geometry: unsafe extern "C" fn(Handle, Handle) -> u32,
    pub commit_scene: unsafe extern "C" fn(Handle),
    pub new_geometry: unsafe extern "C" fn(Handle, u32) -> Handle,
    pub release_geometry: unsafe extern "C" fn(Handle),
    pub set_geometry_build_quality: unsafe extern "C" fn(Handle, u32),
    pub set_new_geometry_buffer: unsafe extern "C" fn(Handle, u32, u32, u32, usize, usize) -> *mut c_void,
    pub commit_geometry: unsafe extern "C" fn(Handle),
    pub intersect1: unsafe extern "C" fn(Handle, *mut IntersectContext, *mut RayHit),
    pub occluded1: unsafe extern "C" fn(Handle, *mut IntersectContext, *mut Ray),
    _library: libloading::Library,
}

/// The shared object opened.
pub const LIBRARY: &str = "libembree3.so.3";

/// The lowest Embree 3 release the layouts above are checked against.
const MIN_VERSION: isize = 3_13_00;

/// The API, or why it cannot be had (library missing, a symbol missing, another major version).
pub fn api() -> Result<&'static Api, String> {
    static API: OnceLock<Result<Api, String>> = OnceLock::new();
    API.get_or_init(open).as_ref().map_err(Clone::clone)
}

fn open() -> Result<Api, String> {
    // SAFETY: opening Embree runs its static initialisers, which only set up its own state.
    let library = unsafe { libloading::Library::new(LIBRARY) }.map_err(|e| {
        format!(
            "the `embree` structure needs the system Embree 3 library ({LIBRARY}), which could not \
             be opened ({e}); on Debian: apt-get install libembree3-3"
        )
    })?;
    macro_rules! symbol {
        ($name:literal) => {
            // SAFETY: each symbol is cast to its prototype in rtcore_*.h (Embree 3.13).
            *unsafe { library.get(concat!($name, "\0").as_bytes()) }
                .map_err(|e| format!("{LIBRARY} lacks `{}` ({e}): not an Embree 3 library", $name))?
        };
    }
    let api = Api {
        new_device: symbol!("rtcNewDevice"),
        release_device: symbol!("rtcReleaseDevice"),
        get_device_error: symbol!("rtcGetDeviceError"),
        get_device_property: symbol!("rtcGetDeviceProperty"),
        set_device_memory_monitor: symbol!("rtcSetDeviceMemoryMonitorFunction"),
        new_scene: symbol!("rtcNewScene"),
        release_scene: symbol!("rtcReleaseScene"),
        set_scene_flags: symbol!("rtcSetSceneFlags"),
        set_scene_build_quality: symbol!("rtcSetSceneBuildQuality"),
        attach_geometry: symbol!("rtcAttachGeometry"),
        commit_scene: symbol!("rtcCommitScene"),
        new_geometry: symbol!("rtcNewGeometry"),
        release_geometry: symbol!("rtcReleaseGeometry"),
        set_geometry_build_quality: symbol!("rtcSetGeometryBuildQuality"),
        set_new_geometry_buffer: symbol!("rtcSetNewGeometryBuffer"),
        commit_geometry: symbol!("rtcCommitGeometry"),
        intersect1: symbol!("rtcIntersect1"),
        occluded1: symbol!("rtcOccluded1"),
        _library: library,
    };
    Ok(api)
}

impl Api {
    /// A new device with `config` (`"threads=N"`), its version checked, or Embree's error.
    pub fn device(&self, config: &CStr) -> Result<Handle, String> {
        // SAFETY: a null device reports the creation error through rtcGetDeviceError(NULL).
        let device = unsafe { (self.new_device)(config.as_ptr()) };
        if device.is_null() {
            let code = unsafe { (self.get_device_error)(std::ptr::null_mut()) };
            return Err(format!("Embree refused to create a device (error {code})"));
        }
        // SAFETY: the device is live.
        let (version, filters, culling) = unsafe {
            (
                (self.get_device_property)(device, DEVICE_PROPERTY_VERSION),
                (self.get_device_property)(device, DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED),
                (self.get_device_property)(device, DEVICE_PROPERTY_BACKFACE_CULLING_ENABLED),
            )
        };
        if !(MIN_VERSION..4_00_00).contains(&version) || filters == 0 || culling != 0 {
            unsafe { (self.release_device)(device) };
            return Err(format!(
                "{LIBRARY} is Embree {}.{}.{}{}{}: the `embree` structure needs Embree 3.13 or a later \
                 3.x built with filter functions and without back-face culling (every structure \
                 here hits both sides)",
                version / 10000,
                version / 100 % 100,
                version % 100,
                if filters == 0 { " without filter functions" } else { "" },
                if culling != 0 { " with back-face culling" } else { "" }
            ));
        }
        Ok(device)
    }

    /// The device's pending error, or Ok.
    pub fn check(&self, device: Handle, doing: &str) -> Result<(), String> {
        // SAFETY: the device is live.
        match unsafe { (self.get_device_error)(device) } {
            0 => Ok(()),
            code => Err(format!(
                "Embree failed while {doing} (error {code}: {})",
                error_name(code)
            )),
        }
    }
}

/// `RTCError`'s names.
fn error_name(code: u32) -> &'static str {
    match code {
        2 => "invalid argument",
        3 => "invalid operation",
        4 => "out of memory",
        5 => "unsupported CPU",
        6 => "cancelled",
        _ => "unknown",
    }
}
