//! Data arrays: values, components, component names and the [`Encoding`] of the file.

/// How the data arrays of a file are stored (see the crate docs for the byte layout).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Encoding {
    /// Text; floats in shortest round-trip form.
    Ascii,
    /// Inline base64 of little-endian binary with a `UInt64` byte-count header.
    #[default]
    Base64,
    /// Raw little-endian binary with a `UInt64` byte-count header in the file's
    /// `<AppendedData encoding="raw">` section: the smallest and fastest form.
    Appended,
}

/// The values of a data array, borrowed from the caller; components interleaved per
/// tuple.
#[derive(Clone, Copy, Debug)]
pub enum Values<'a> {
    /// `Float64`.
    F64(&'a [f64]),
    /// `Int32`.
    I32(&'a [i32]),
    /// `Int64`.
    I64(&'a [i64]),
    /// `UInt8`.
    U8(&'a [u8]),
}

impl Values<'_> {
    /// Number of values (tuples × components).
    pub fn len(&self) -> usize {
        match self {
            Values::F64(v) => v.len(),
            Values::I32(v) => v.len(),
            Values::I64(v) => v.len(),
            Values::U8(v) => v.len(),
        }
    }

    /// Whether there are no values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl<'a> From<&'a [f64]> for Values<'a> {
    fn from(v: &'a [f64]) -> Self {
        Values::F64(v)
    }
}
impl<'a> From<&'a [i32]> for Values<'a> {
    fn from(v: &'a [i32]) -> Self {
        Values::I32(v)
    }
}
impl<'a> From<&'a [i64]> for Values<'a> {
    fn from(v: &'a [i64]) -> Self {
        Values::I64(v)
    }
}
impl<'a> From<&'a [u8]> for Values<'a> {
    fn from(v: &'a [u8]) -> Self {
        Values::U8(v)
    }
}

/// One named data array.
#[derive(Clone, Copy, Debug)]
pub struct DataArray<'a> {
    /// The array's name (any text; escaped in the file).
    pub name: &'a str,
    /// Components per tuple (≥ 1).
    pub components: usize,
    /// The values, `components` per tuple.
    pub values: Values<'a>,
    /// Names of the components, written as `ComponentName0`, … (none, or one per
    /// component).
    pub component_names: &'a [&'a str],
}

impl<'a> DataArray<'a> {
    /// An array of `components` values per tuple, without component names.
    pub fn new(name: &'a str, components: usize, values: impl Into<Values<'a>>) -> Self {
        Self {
            name,
            components,
            values: values.into(),
            component_names: &[],
        }
    }

    /// The same array with component names (one per component; see
    /// [`component_names`]).
    pub fn with_component_names(self, names: &'a [&'a str]) -> Self {
        Self {
            component_names: names,
            ..self
        }
    }

    /// Number of tuples (values / components, rounded down).
    pub fn tuples(&self) -> usize {
        self.values.len() / self.components.max(1)
    }

    /// `Ok` if the array holds `n` whole tuples and its component names fit; else what is
    /// wrong, naming the array and `what` (e.g. `"point data"`).
    pub(crate) fn check(&self, n: usize, what: &str) -> Result<(), String> {
        let (name, c, len) = (self.name, self.components, self.values.len());
        if c == 0 {
            return Err(format!("{what} array `{name}` has 0 components"));
        }
        if len != n * c {
            return Err(format!(
                "{what} array `{name}` has {len} values, expected {n} tuples of {c} components"
            ));
        }
        if !self.component_names.is_empty() && self.component_names.len() != c {
            return Err(format!(
                "{what} array `{name}` has {} component names for {c} components",
                self.component_names.len()
            ));
        }
        Ok(())
    }
}

/// The point or cell data of a piece: arrays and, optionally, the name of the array that
/// ParaView colours by when the file is opened (the `Scalars` attribute).
#[derive(Clone, Copy, Debug, Default)]
pub struct Attributes<'a> {
    /// The arrays, written in this order.
    pub arrays: &'a [DataArray<'a>],
    /// The active scalars (`<PointData Scalars="…">`), if any.
    pub scalars: Option<&'a str>,
}

impl<'a> Attributes<'a> {
    /// The arrays, no active scalars.
    pub fn new(arrays: &'a [DataArray<'a>]) -> Self {
        Self {
            arrays,
            scalars: None,
        }
    }

    /// The same with `name` as active scalars.
    pub fn with_scalars(self, name: &'a str) -> Self {
        Self {
            scalars: Some(name),
            ..self
        }
    }

    pub(crate) fn check(&self, n: usize, what: &str) -> Result<(), String> {
        for (k, a) in self.arrays.iter().enumerate() {
            a.check(n, what)?;
            if self.arrays[..k].iter().any(|b| b.name == a.name) {
                return Err(format!("{what} array `{}` given twice", a.name));
            }
        }
        Ok(())
    }
}

/// Component names as ParaView shows them, for [`DataArray::with_component_names`].
///
/// Tensors with 6 and 9 components are recognised by ParaView without names (it names
/// them the same way); plane tensors (3 and 4 components) are not, and the names say
/// which component is which.
pub mod component_names {
    /// A vector.
    pub const VECTOR: [&str; 3] = ["X", "Y", "Z"];
    /// A plane symmetric tensor `[xx, yy, xy]`.
    pub const SYMMETRIC_2D: [&str; 3] = ["XX", "YY", "XY"];
    /// A symmetric tensor in VTK's order `[xx, yy, zz, xy, yz, xz]`.
    pub const SYMMETRIC_3D: [&str; 6] = ["XX", "YY", "ZZ", "XY", "YZ", "XZ"];
    /// A plane full tensor, row-major `[xx, xy, yx, yy]`.
    pub const TENSOR_2D: [&str; 4] = ["XX", "XY", "YX", "YY"];
    /// A full tensor, row-major `[xx, xy, xz, yx, yy, yz, zx, zy, zz]`.
    pub const TENSOR_3D: [&str; 9] = ["XX", "XY", "XZ", "YX", "YY", "YZ", "ZX", "ZY", "ZZ"];
}
