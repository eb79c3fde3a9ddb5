//! The paper's published numbers, typed in from its tables (Feixas, del Acebo, Bekaert, Sbert, EG 1999),
//! kept as the printed text so that the comparison shows exactly what the paper shows.

/// Table 1 (fig. 2, 512 cubes): `(placement, lines, H_s, I_s, E(MSE))`; H_p = 11.541 for all.
pub const TABLE1: [(char, u64, &str, &str, &str); 6] = [
    ('a', 1_000_000, "6.370", "5.171", "1284.6"),
    ('a', 10_000_000, "6.761", "4.779", "1286.7"),
    ('b', 1_000_000, "5.072", "6.469", "949.3"),
    ('b', 10_000_000, "5.271", "6.270", "950.1"),
    ('c', 1_000_000, "4.674", "6.867", "898.8"),
    ('c', 10_000_000, "4.849", "6.692", "900.9"),
];
/// Table 1's caption: the positional entropy of the three scenes.
pub const TABLE1_HP: &str = "11.541";

/// Table 2 (fig. 3, empty cube with N x N patches per face): `(N, lines, H_s, I_s, I_s^c)`.
pub const TABLE2: [(usize, u64, &str, &str, &str); 9] = [
    (10, 100_000, "6.482", "2.747", "1.610"),
    (10, 10_000_000, "7.821", "1.408", "1.612"),
    (10, 1_000_000_000, "7.838", "1.391", "1.610"),
    (20, 100_000, "5.342", "5.887", "1.608"),
    (20, 10_000_000, "9.420", "1.809", "1.611"),
    (20, 1_000_000_000, "9.731", "1.498", "1.610"),
    (30, 100_000, "4.313", "8.086", "1.610"),
    (30, 10_000_000, "9.684", "2.715", "1.611"),
    (30, 1_000_000_000, "10.852", "1.547", "1.610"),
];

/// Table 3 (fig. 2a): `(lines, I_s, I_s^c)`.
pub const TABLE3: [(u64, &str, &str); 4] = [
    (10_000, "8.773", "5.650"),
    (100_000, "6.398", "5.636"),
    (1_000_000, "5.171", "5.631"),
    (10_000_000, "4.779", "5.632"),
];

/// Table 4 (regular solids and the Cornell box, 10^6 lines each): `(paper's name, I_s^c)`.
pub const TABLE4: [(&str, &str); 7] = [
    ("sphere", "0"),
    ("icosahedron", "0.5428"),
    ("dodecahedron", "0.8254"),
    ("octahedron", "1.2583"),
    ("cube", "1.6093"),
    ("tetrahedron", "2.6227"),
    ("Cornell box", "2.800"),
];
/// Lines per scene in Tables 4 and 5.
pub const TABLE45_LINES: u64 = 1_000_000;

/// Table 5 (fig. 4, tables and chairs, 10^6 lines each): `(layout, I_s^c)`.
pub const TABLE5: [(char, &str); 6] = [
    ('a', "3.837"),
    ('b', "4.102"),
    ('c', "5.023"),
    ('d', "5.043"),
    ('e', "5.044"),
    ('f', "5.089"),
];

/// Lines per scene in Tables 6 and 7.
pub const TABLE67_LINES: u64 = 100_000_000;

/// Table 6 (fig. 5, cubes finer), stages a..f: `(I_s, I_s^c, I_s / I_s^c)`.
pub const TABLE6: [(&str, &str, &str); 6] = [
    ("5.492", "6.430", "0.854"),
    ("5.054", "5.678", "0.890"),
    ("4.672", "5.177", "0.902"),
    ("4.395", "4.867", "0.903"),
    ("4.356", "5.015", "0.869"),
    ("4.775", "6.055", "0.789"),
];

/// Table 7 (fig. 6, walls finer), stages a..f: `(I_s, I_s^c, I_s / I_s^c)`.
pub const TABLE7: [(&str, &str, &str); 6] = [
    ("5.110", "6.430", "0.795"),
    ("4.809", "5.678", "0.847"),
    ("4.543", "5.177", "0.878"),
    ("4.348", "4.867", "0.893"),
    ("4.483", "5.015", "0.894"),
    ("4.932", "6.055", "0.814"),
];

/// Table 8 (fig. 9, the labyrinth with radiosity 1 everywhere): visibility and radiosity
/// `(H_p, H_s, I_s)`. The paper does not say how many lines it cast.
pub const TABLE8_VISIBILITY: (&str, &str, &str) = ("10.6883", "6.47804", "4.21022");
/// Table 8, radiosity row.
pub const TABLE8_RADIOSITY: (&str, &str, &str) = ("10.6842", "6.47833", "4.20591");

/// Table 9 (fig. 10, Cornell box meshes): `(fig., mesh, patches, lines, H_p, H_s, I_s)`, radiosity
/// measures (eqs. 33-35).
pub const TABLE9: [(char, &str, usize, u64, &str, &str, &str); 6] = [
    ('a', "uniform", 464, 16_500_000, "6.94", "2.52", "4.42"),
    ('b', "power", 453, 16_500_000, "8.46", "2.59", "5.87"),
    ('c', "smooth", 459, 16_500_000, "7.51", "2.56", "4.94"),
    ('d', "uniform", 1146, 41_200_000, "8.30", "2.75", "5.55"),
    ('e', "power", 1143, 41_200_000, "9.80", "2.82", "6.98"),
    ('f', "smooth", 1146, 41_200_000, "8.98", "2.80", "6.18"),
];
