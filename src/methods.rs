//! The one table of methods.
//!
//! Every run-time mapping of a method follows from the rows of [`methods!`]: the [`Method`] enum
//! with its names (command line, Python, JSON reports), report labels and C ABI numbers, and
//! the dispatch of [`AnyHierarchy`](crate::AnyHierarchy) and [`Scene`](crate::Scene). A
//! fourth method is one file in `bv/` implementing [`BoundingVolume`] plus one row here.
//!
//! The table is a macro that hands its rows to a callback macro, so each user generates its
//! code (an enum with a variant per method, a `match` with an arm per method) from the same rows.

use crate::bv::BoundingVolume;
use crate::error::Error;

/// `methods!(path::to::callback { args })` calls `callback! { { args } rows }` with one row
/// `(Type, number, "name", [aliases], "label")` per method: `Type` is the method's type in [`crate::bv`] and its [`Method`] variant;
/// `number` its stable number in the C ABI (`DHCD_METHOD_*`); `"name"` its name on the
/// command line, in Python and in JSON reports; `aliases` other names accepted when parsing;
/// `"label"` its name in human-readable reports.
///
/// Exported (hidden) only because [`for_each_method!`](crate::for_each_method) expands to it.
#[doc(hidden)]
#[macro_export]
macro_rules! __methods {
    ($($callback:tt)::+ { $($args:tt)* }) => {
        $($callback)::+! { { $($args)* }
            (Dh, 0, "dh", [], "DH")
            (Sphere, 1, "sphere", ["sbv"], "sphere (SBV)")
            (Aabb, 2, "aabb", [], "AABB")
        }
    };
}
pub(crate) use crate::__methods as methods;

/// Runs `expr` once per method of the table, in table order, with the type `K` naming the method:
/// generic code (tests, benchmarks) covers every method, a method added later included.
///
/// ```
/// use dhcd::{bv::BoundingVolume, for_each_method, Hierarchy, Options};
/// let mesh = dhcd::shapes::icosphere(1, 1.0, [0.0; 3]);
/// let mut bytes = Vec::new();
/// for_each_method!(K => bytes.push(Hierarchy::<K>::new(&mesh, Options::default())?.bytes_per_node()));
/// assert_eq!(bytes, [8, 16, 24]);
/// # Ok::<(), dhcd::Error>(())
/// ```
#[macro_export]
macro_rules! for_each_method {
    ($k:ident => $e:expr) => {
        $crate::__methods!($crate::__for_each_method_arms { $k, $e })
    };
}

#[doc(hidden)]
#[macro_export]
macro_rules! __for_each_method_arms {
    ({ $k:ident, $e:expr } $(($kind:ident, $($rest:tt)*))*) => {
        $({
            type $k = $crate::bv::$kind;
            $e;
        })*
    };
}

macro_rules! define_method {
    ({} $(($kind:ident, $code:literal, $name:literal, [$($alias:literal),*], $label:literal))*) => {
        /// A method (one of the bounding-volume hierarchies the paper compares), chosen at
        /// run time: one variant per row of the table of methods (`src/methods.rs`).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[non_exhaustive]
        pub enum Method {
            $(
                #[doc = concat!("`", $name, "`: [`", stringify!($kind), "`](crate::bv::", stringify!($kind), ").")]
                $kind,
            )*
        }

        impl Method {
            /// Every method, in table order.
            pub const ALL: [Method; [$($code),*].len()] = [$(Method::$kind),*];

            /// The name on the command line, in Python and in JSON reports.
            pub const fn name(self) -> &'static str {
                match self { $(Method::$kind => $name,)* }
            }

            /// Other names accepted by [`Method::from_name`] (e.g. `sbv`, the paper's name).
            #[doc(hidden)]
            pub const fn aliases(self) -> &'static [&'static str] {
                match self { $(Method::$kind => &[$($alias),*],)* }
            }

            /// The name in human-readable reports.
            pub const fn label(self) -> &'static str {
                match self { $(Method::$kind => $label,)* }
            }

            /// The method's number in the C ABI (`DHCD_METHOD_*`); stable across versions.
            pub const fn code(self) -> i32 {
                match self { $(Method::$kind => $code,)* }
            }

            /// The method with C ABI number `code`.
            pub const fn from_code(code: i32) -> Option<Method> {
                match code {
                    $($code => Some(Method::$kind),)*
                    _ => None,
                }
            }

            /// Size of one node record in bytes (8, 16, 24 for DH, sphere, AABB).
            pub fn bytes_per_node(self) -> usize {
                match self {
                    $(Method::$kind => std::mem::size_of::<<crate::bv::$kind as BoundingVolume>::Record>(),)*
                }
            }
        }

        // Each method's `BoundingVolume::METHOD` is its own row.
        $(const _: () = assert!(matches!(<crate::bv::$kind as BoundingVolume>::METHOD, Method::$kind));)*
    };
}
methods!(define_method {});

impl Method {
    /// The method named `name` (case-insensitive; a name or an alias).
    pub fn from_name(name: &str) -> Option<Method> {
        let name = name.to_ascii_lowercase();
        Method::ALL
            .into_iter()
            .find(|m| m.name() == name || m.aliases().contains(&name.as_str()))
    }

    /// The names of all methods, for messages: `dh, sphere, aabb`.
    #[doc(hidden)]
    pub fn names() -> String {
        Method::ALL.map(Method::name).join(", ")
    }

    /// Position in [`Method::ALL`] (e.g. to pick a colour from a palette).
    #[doc(hidden)]
    pub fn index(self) -> usize {
        Method::ALL.iter().position(|&m| m == self).unwrap_or(0)
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Method {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::from_name(s).ok_or_else(|| Error::UnknownMethod {
            got: s.to_owned(),
            expected: Method::names(),
        })
    }
}

/// Defines `$vis enum $name` with one variant per method, each holding `$wrap<K>` for the method's type
/// `K` (`$wrap` a type alias or type with one parameter), plus `From<$wrap<K>>` and `method()`.
macro_rules! method_enum {
    ({ $(#[$attr:meta])* $vis:vis enum $name:ident($wrap:ident) } $(($kind:ident, $($rest:tt)*))*) => {
        $(#[$attr])*
        $vis enum $name {
            $(#[doc = concat!("A [`", stringify!($kind), "`](crate::bv::", stringify!($kind), ") hierarchy.")]
            $kind($wrap<crate::bv::$kind>),)*
        }

        $(impl From<$wrap<crate::bv::$kind>> for $name {
            fn from(x: $wrap<crate::bv::$kind>) -> Self {
                $name::$kind(x)
            }
        })*

        impl $name {
            /// The method of the hierarchies inside.
            $vis fn method(&self) -> crate::methods::Method {
                match self { $($name::$kind(_) => crate::methods::Method::$kind,)* }
            }
        }
    };
}
pub(crate) use method_enum;

/// `match_method!(Enum, value, x => expr)`: `expr` with `x` bound to the contents of whichever
/// variant `value` (an `Enum` defined by [`method_enum!`], or a reference to one) holds.
macro_rules! match_method {
    ($name:ident, $value:expr, $x:ident => $e:expr) => {
        $crate::methods::methods!($crate::methods::match_method_arms {
            $name,
            $value,
            $x,
            $e
        })
    };
}
pub(crate) use match_method;

macro_rules! match_method_arms {
    ({ $name:ident, $value:expr, $x:ident, $e:expr } $(($kind:ident, $($rest:tt)*))*) => {
        match $value {
            $($name::$kind($x) => $e,)*
        }
    };
}
pub(crate) use match_method_arms;

/// `match_method_pair!(Enum, a, b, x, y => expr)`: `Ok(expr)` with `x`, `y` bound to the
/// contents of `a` and `b` when they hold the same method, else [`Error::MethodMismatch`].
macro_rules! match_method_pair {
    ($name:ident, $a:expr, $b:expr, $x:ident, $y:ident => $e:expr) => {
        $crate::methods::methods!($crate::methods::match_method_pair_arms {
            $name,
            $a,
            $b,
            $x,
            $y,
            $e
        })
    };
}
pub(crate) use match_method_pair;

macro_rules! match_method_pair_arms {
    ({ $name:ident, $a:expr, $b:expr, $x:ident, $y:ident, $e:expr } $(($kind:ident, $($rest:tt)*))*) => {
        match ($a, $b) {
            $(($name::$kind($x), $name::$kind($y)) => Ok($e),)*
            (a, b) => Err($crate::error::Error::MethodMismatch {
                a: a.method().name(),
                b: b.method().name(),
            }),
        }
    };
}
pub(crate) use match_method_pair_arms;

/// `with_method!(method, K => expr)`: `expr` with the type `K` naming the method `method` names.
macro_rules! with_method {
    ($method:expr, $k:ident => $e:expr) => {
        $crate::methods::methods!($crate::methods::with_method_arms { $method, $k, $e })
    };
}
pub(crate) use with_method;

macro_rules! with_method_arms {
    ({ $method:expr, $k:ident, $e:expr } $(($kind:ident, $($rest:tt)*))*) => {
        match $method {
            $($crate::methods::Method::$kind => {
                type $k = $crate::bv::$kind;
                $e
            })*
        }
    };
}
pub(crate) use with_method_arms;
