//! Opaque handles: a boxed value behind a tag that says its kind, so a
//! plan passed where a project is expected is refused (A001) instead of
//! being read as one. (A freed or made-up pointer cannot be detected.)

use crate::boundary::bad_argument;
use btc_api::Error;

/// The kinds of handles, and their tags.
pub(crate) trait Kind {
    const TAG: u64;
    const NAME: &'static str;
}

impl Kind for btc_api::Project {
    const TAG: u64 = 0x6274_635f_7072_6f6a; // "btc_proj"
    const NAME: &'static str = "btc_project";
}
impl Kind for btc_api::Plan {
    const TAG: u64 = 0x6274_635f_706c_616e; // "btc_plan"
    const NAME: &'static str = "btc_plan";
}
impl Kind for btc_api::Tree {
    const TAG: u64 = 0x6274_635f_7472_6565; // "btc_tree"
    const NAME: &'static str = "btc_tree";
}
impl Kind for btc_api::Agent {
    const TAG: u64 = 0x6274_635f_6167_6e74; // "btc_agnt"
    const NAME: &'static str = "btc_agent";
}

/// The tag at offset 0 of every handle (the `repr(C)` wrappers hold a
/// `Handle` as their only field).
#[repr(C)]
pub(crate) struct Handle<T> {
    tag: u64,
    pub(crate) value: T,
}

impl<T: Kind> Handle<T> {
    pub(crate) fn new(value: T) -> Handle<T> {
        Handle { tag: T::TAG, value }
    }
}

/// Refuses a null pointer and a handle of another kind: every handle
/// starts with its tag, read before the handle is read as this kind.
unsafe fn check<T: Kind>(ptr: *const u64, arg: &str) -> Result<(), Error> {
    if ptr.is_null() {
        return Err(bad_argument(format!("`{arg}` is a null pointer")));
    }
    if *ptr != T::TAG {
        return Err(bad_argument(format!(
            "`{arg}` is not a live {} (another kind of handle, or one already freed)",
            T::NAME
        )));
    }
    Ok(())
}

/// The value behind a handle.
///
/// # Safety
/// `ptr` is null or a handle btc returned that is not freed.
pub(crate) unsafe fn get<'a, H: 'a, T: Kind + 'a>(
    ptr: *const H,
    arg: &str,
    field: impl FnOnce(&'a H) -> &'a Handle<T>,
) -> Result<&'a T, Error> {
    check::<T>(ptr as *const u64, arg)?;
    Ok(&field(&*ptr).value)
}

/// # Safety
/// As [`get`], and no other reference to the handle is in use.
pub(crate) unsafe fn get_mut<'a, H: 'a, T: Kind + 'a>(
    ptr: *mut H,
    arg: &str,
    field: impl FnOnce(&'a mut H) -> &'a mut Handle<T>,
) -> Result<&'a mut T, Error> {
    check::<T>(ptr as *const u64, arg)?;
    Ok(&mut field(&mut *ptr).value)
}

/// Takes the value out of a handle and frees the handle.
///
/// # Safety
/// As [`get_mut`].
pub(crate) unsafe fn take<H, T: Kind>(
    ptr: *mut H,
    arg: &str,
    field: impl FnOnce(H) -> Handle<T>,
) -> Result<T, Error> {
    check::<T>(ptr as *const u64, arg)?;
    Ok(field(*Box::from_raw(ptr)).value)
}

/// Frees a handle; null and handles of another kind are ignored.
///
/// # Safety
/// `ptr` is null or a handle btc returned that is not freed.
pub(crate) unsafe fn free<H, T: Kind>(ptr: *mut H, field: impl FnOnce(&mut H) -> &mut Handle<T>) {
    if ptr.is_null() || *(ptr as *const u64) != T::TAG {
        return;
    }
    let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let mut boxed = Box::from_raw(ptr);
        field(&mut boxed).tag = 0;
        drop(boxed);
    }));
}
