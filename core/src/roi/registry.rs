//! The one registry of detectors: [`detector_registry!`](crate::detector_registry)
//! turns one line per detector into everything that dispatches on a method.
//!
//! From the entries `Variant(field) => path::Detector` it declares:
//!
//! - a method enum (`Method`): `ALL` in registry order, `name` (the detector's
//!   [`Detector::NAME`]), `from_name`, `scratch_bytes` (the size of its [`Scratch`]),
//!   `default_params`, `Display`;
//! - a parameter enum (`Params`), one variant per detector holding its parameter
//!   struct: `method`, `box_rule`, `set_box_rule`, `validate`, `Display` (the
//!   detector's `name=value` pairs);
//! - a bank (`Detectors`) holding every detector's scratch memory, built by a
//!   `const fn` (so it can be a `static` on flight hardware), with `detect(&Params,
//!   &Frame)`.
//!
//! The core's five detectors are registered in [`super`] as [`super::Method`],
//! [`super::Params`] and [`super::Detectors`]; the host CLI, evaluation, tuning,
//! plots, the firmware and the tests all dispatch through them. Adding a detector is
//! its module (parameters implementing [`Detector`], `Default`, `Copy`, `Display`) plus
//! one line in that registry; the test `core/tests/registry.rs` declares a
//! registry with a toy detector to show it.
//!
//! [`Detector`]: super::Detector
//! [`Detector::NAME`]: super::Detector::NAME
//! [`Scratch`]: super::Scratch

/// Declares a detector registry: a method enum, a parameter enum and a scratch bank
/// from one entry per detector (see the [module documentation](crate::roi::registry)).
///
/// ```
/// use tirroi_core::roi::{adaptive::Adaptive, otsu::Otsu};
/// use tirroi_core::{Detector, Frame};
///
/// tirroi_core::detector_registry! {
///     /// Two of the core's detectors.
///     pub enum Pick;
///     /// Their parameters.
///     pub enum PickParams;
///     /// Their scratch memory.
///     pub struct PickBank;
///     /// Otsu's threshold.
///     Otsu(otsu) => Otsu,
///     /// The local-mean threshold.
///     Adaptive(adaptive) => Adaptive,
/// }
///
/// assert_eq!(Pick::ALL, [Pick::Otsu, Pick::Adaptive]);
/// assert_eq!(Pick::from_name("adaptive"), Some(Pick::Adaptive));
/// let pixels = [0u16; 16 * 8];
/// let frame = Frame::new(&pixels, 16, 8, 14).unwrap();
/// let mut bank = Box::new(PickBank::new());
/// let found = bank.detect(&Pick::Otsu.default_params(), &frame).unwrap();
/// assert_eq!(found.roi, None);
/// ```
#[macro_export]
macro_rules! detector_registry {
    (
        $(#[$method_meta:meta])*
        $vis:vis enum $Method:ident;
        $(#[$params_meta:meta])*
        $params_vis:vis enum $Params:ident;
        $(#[$bank_meta:meta])*
        $bank_vis:vis struct $Bank:ident;
        $(
            $(#[$entry_meta:meta])*
            $Variant:ident($field:ident) => $Det:ty
        ),+ $(,)?
    ) => {
        $(#[$method_meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        $vis enum $Method {
            $(
                $(#[$entry_meta])*
                $Variant,
            )+
        }

        impl $Method {
            /// Every registered method, in registry order.
            pub const ALL: [$Method; [$(stringify!($Variant)),+].len()] =
                [$($Method::$Variant),+];

            /// Position in [`Self::ALL`] (registry order).
            #[inline]
            pub const fn index(self) -> usize {
                self as usize
            }

            /// The lower-case name used on the command line (`Detector::NAME`).
            pub const fn name(self) -> &'static str {
                match self {
                    $($Method::$Variant => <$Det as $crate::roi::Detector>::NAME,)+
                }
            }

            /// The method of a lower-case name, `None` for any other string.
            pub fn from_name(name: &str) -> ::core::option::Option<$Method> {
                $Method::ALL.into_iter().find(|m| m.name() == name)
            }

            /// Bytes of scratch memory the method needs beyond the input frame (its
            /// `Scratch`) at the reference capacity (328×248), on this target.
            pub const fn scratch_bytes(self) -> usize {
                self.scratch_bytes_for::<$crate::capacity::Reference>()
            }

            /// Bytes of scratch memory the method needs at capacity `C`, on this
            /// target.
            pub const fn scratch_bytes_for<C: $crate::capacity::FrameCapacity>(self) -> usize {
                match self {
                    $($Method::$Variant => ::core::mem::size_of::<
                        $crate::roi::Scratch<<$Det as $crate::roi::Detector>::Work<C>, C>,
                    >(),)+
                }
            }

            /// The detector's default parameters.
            #[inline]
            pub fn default_params(self) -> $Params {
                match self {
                    $($Method::$Variant => $Params::$Variant(<$Det as ::core::default::Default>::default()),)+
                }
            }
        }

        impl ::core::fmt::Display for $Method {
            fn fmt(&self, f: &mut ::core::fmt::Formatter<'_>) -> ::core::fmt::Result {
                f.write_str(self.name())
            }
        }

        $(#[$params_meta])*
        #[derive(Debug, Clone, Copy, PartialEq)]
        $params_vis enum $Params {
            $(
                $(#[$entry_meta])*
                $Variant($Det),
            )+
        }

        impl $Params {
            /// The method these parameters belong to.
            #[inline]
            pub const fn method(&self) -> $Method {
                match self {
                    $($Params::$Variant(_) => $Method::$Variant,)+
                }
            }

            /// The mask-to-box rule (`Detector::box_rule`).
            #[inline]
            pub fn box_rule(&self) -> $crate::roi::BoxRule {
                match self {
                    $($Params::$Variant(p) => $crate::roi::Detector::box_rule(p),)+
                }
            }

            /// Sets the mask-to-box rule (`Detector::set_box_rule`; a detector
            /// without one ignores it).
            #[inline]
            pub fn set_box_rule(&mut self, rule: $crate::roi::BoxRule) {
                match self {
                    $($Params::$Variant(p) => $crate::roi::Detector::set_box_rule(p, rule),)+
                }
            }

            /// Checks the parameters against their documented bounds.
            ///
            /// # Errors
            /// `DetectError::InvalidParameter` naming the first field out of bounds.
            #[inline]
            pub fn validate(&self) -> ::core::result::Result<(), $crate::roi::DetectError> {
                match self {
                    $($Params::$Variant(p) => $crate::roi::Detector::validate(p),)+
                }
            }
        }

        impl ::core::fmt::Display for $Params {
            /// The parameters as `name=value` pairs separated by spaces.
            fn fmt(&self, f: &mut ::core::fmt::Formatter<'_>) -> ::core::fmt::Result {
                match self {
                    $($Params::$Variant(p) => ::core::fmt::Display::fmt(p, f),)+
                }
            }
        }

        $(#[$bank_meta])*
        $bank_vis struct $Bank<C: $crate::capacity::FrameCapacity = $crate::capacity::Reference> {
            $(
                $field: $crate::roi::Scratch<<$Det as $crate::roi::Detector>::Work<C>, C>,
            )+
        }

        impl $Bank {
            /// Fresh scratch for every detector at the reference capacity, 328×248 (a
            /// `const fn`, so the bank can be a `static`).
            pub const fn new() -> Self {
                Self::for_capacity()
            }
        }

        impl<C: $crate::capacity::FrameCapacity> ::core::clone::Clone for $Bank<C> {
            fn clone(&self) -> Self {
                $Bank {
                    $($field: ::core::clone::Clone::clone(&self.$field),)+
                }
            }
        }

        impl<C: $crate::capacity::FrameCapacity> $Bank<C> {
            $(
                /// This detector's scratch in the bank, for a caller that runs it itself
                /// (e.g. a sequence tracker holding its own state across frames).
                pub fn $field(
                    &mut self,
                ) -> &mut $crate::roi::Scratch<<$Det as $crate::roi::Detector>::Work<C>, C> {
                    &mut self.$field
                }
            )+

            /// Fresh scratch for every detector at capacity `C` (a `const fn`).
            pub const fn for_capacity() -> Self {
                $Bank {
                    $(
                        $field: $crate::roi::Scratch::for_capacity(),
                    )+
                }
            }

            /// Runs the detector of `params` on `frame` in its scratch.
            ///
            /// # Errors
            /// `DetectError` when the parameters are out of bounds or the frame
            /// exceeds capacity `C`.
            #[inline]
            pub fn detect(
                &mut self,
                params: &$Params,
                frame: &$crate::frame::Frame<'_>,
            ) -> ::core::result::Result<$crate::roi::Detection, $crate::roi::DetectError> {
                match params {
                    $($Params::$Variant(p) => $crate::roi::Detector::detect(p, frame, &mut self.$field),)+
                }
            }
        }

        impl<C: $crate::capacity::FrameCapacity> $Bank<C> {
            /// Runs `method` with its default parameters on `frame` (the parameters are
            /// constants here, so the compiler specialises each detector for them, as
            /// flight code calling it directly would be).
            ///
            /// # Errors
            /// `DetectError` when the default parameters are out of bounds (never for
            /// the core's detectors, by their tests) or the frame exceeds capacity `C`.
            #[inline(always)]
            pub fn detect_default(
                &mut self,
                method: $Method,
                frame: &$crate::frame::Frame<'_>,
            ) -> ::core::result::Result<$crate::roi::Detection, $crate::roi::DetectError> {
                match method {
                    $($Method::$Variant => $crate::roi::Detector::detect(
                        &<$Det as ::core::default::Default>::default(),
                        frame,
                        &mut self.$field,
                    ),)+
                }
            }
        }

        impl<C: $crate::capacity::FrameCapacity> ::core::default::Default for $Bank<C> {
            fn default() -> Self {
                Self::for_capacity()
            }
        }
    };
}
