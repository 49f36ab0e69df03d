//! Named choices (intersection methods, offset methods, accelerators, shading models): the one
//! list of each enum's variants with the names scene files, the CLI and the viewer's menus use.
//!
//! The names are the serde names (kebab-case), so a scene file, `--accel bvh` and the stats
//! JSON spell a choice the same way; a test holds each `name` to its serde spelling.

/// An enum whose variants a user picks by name.
pub trait Choice: Copy + PartialEq + Default + std::fmt::Debug + Send + Sync + 'static {
    /// Every variant, in the order menus and help list them.
    const ALL: &'static [Self];

    /// The variant's name in files and on the command line (kebab-case).
    fn name(self) -> &'static str;

    /// One line on what the variant does, for `--help` and tooltips.
    fn help(self) -> &'static str;

    /// The variant called `name`, if any.
    fn from_name(name: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|c| c.name() == name)
    }
}

/// Implements [`Choice`] from a list of `Variant => ("name", "help")`.
macro_rules! choice {
    ($ty:ty { $($variant:ident => ($name:literal, $help:literal)),+ $(,)? }) => {
        impl $crate::choice::Choice for $ty {
            const ALL: &'static [Self] = &[$(<$ty>::$variant),+];
            fn name(self) -> &'static str {
                match self { $(<$ty>::$variant => $name),+ }
            }
            fn help(self) -> &'static str {
                match self { $(<$ty>::$variant => $help),+ }
            }
        }
    };
}
pub(crate) use choice;

#[cfg(test)]
mod tests {
    use super::Choice;
    use crate::accel::AccelKind;
    use crate::geometry::{OffsetMethod, SphereMethod, TriangleMethod};
    use crate::scene::Shading;

    fn names_are_serde_names<T: Choice + serde::Serialize>() {
        assert!(!T::ALL.is_empty());
        for &c in T::ALL {
            let serde = serde_json::to_value(c).expect("serialises");
            assert_eq!(serde.as_str(), Some(c.name()), "{c:?}");
            assert_eq!(T::from_name(c.name()), Some(c));
            assert!(!c.help().is_empty());
        }
        assert!(T::ALL.contains(&T::default()));
        assert_eq!(T::from_name("no-such-choice"), None);
    }

    #[test]
    fn every_choice_is_named_as_serde_names_it() {
        names_are_serde_names::<AccelKind>();
        names_are_serde_names::<OffsetMethod>();
        names_are_serde_names::<SphereMethod>();
        names_are_serde_names::<TriangleMethod>();
        names_are_serde_names::<Shading>();
        names_are_serde_names::<crate::geometry::ShadingNormals>();
        names_are_serde_names::<crate::scene::NormalsMode>();
    }
}
