//! Counted nouns in messages and labels: "1 node", "2 nodes", "1 sample", "3 notes". Every
//! count shown to a user goes through [`count`], so no label says "1 nodes".

/// `n` and `noun` in the number `n` asks for: `count(1, "node")` is "1 node",
/// `count(2, "node")` is "2 nodes". `noun` is the singular; the plural follows English
/// spelling for the words raytree counts (s, x, ch, sh take -es; a consonant and y, -ies).
pub fn count(n: impl Count, noun: &str) -> String {
    let n = n.to_u64();
    format!("{n} {}", noun_for(n, noun))
}

/// A number of things: the integer types counts come in.
pub trait Count {
    fn to_u64(self) -> u64;
}

macro_rules! counts {
    ($($t:ty),*) => {$(
        impl Count for $t {
            fn to_u64(self) -> u64 {
                self as u64
            }
        }
    )*};
}
counts!(u8, u16, u32, u64, usize);

/// `noun` as `n` of it is written, without the number.
pub fn noun_for(n: u64, noun: &str) -> String {
    if n == 1 {
        return noun.to_string();
    }
    let consonant_y = noun.ends_with('y')
        && !noun
            .chars()
            .rev()
            .nth(1)
            .is_some_and(|c| "aeiou".contains(c));
    if consonant_y {
        format!("{}ies", &noun[..noun.len() - 1])
    } else if ["s", "x", "ch", "sh"].iter().any(|e| noun.ends_with(e)) {
        format!("{noun}es")
    } else {
        format!("{noun}s")
    }
}

/// [`count`] with a large number shortened: "57k triangles", "1.2M triangles" (exact below
/// 10,000).
pub fn count_short(n: impl Count, noun: &str) -> String {
    let n = n.to_u64();
    let number = match n {
        0..10_000 => n.to_string(),
        10_000..1_000_000 => format!("{}k", (n + 500) / 1000),
        _ => format!("{:.1}M", n as f64 / 1e6),
    };
    format!("{number} {}", noun_for(n, noun))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_is_singular_and_the_rest_plural() {
        assert_eq!(count(1u32, "node"), "1 node");
        assert_eq!(count(0u32, "node"), "0 nodes");
        assert_eq!(count(2u64, "sample"), "2 samples");
        assert_eq!(count(3u32, "box"), "3 boxes");
        assert_eq!(count(2u32, "mesh"), "2 meshes");
        assert_eq!(count(2u32, "ray"), "2 rays");
        assert_eq!(count(2u32, "primary"), "2 primaries");
        assert_eq!(count(1u32, "primary"), "1 primary");
        assert_eq!(count_short(9_999u32, "triangle"), "9999 triangles");
        assert_eq!(count_short(57_311u32, "triangle"), "57k triangles");
        assert_eq!(count_short(1_234_567u32, "triangle"), "1.2M triangles");
    }
}
