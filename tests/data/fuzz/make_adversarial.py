"""Hand-made adversarial MSH inputs (allocation bombs, extreme tags and counts, bad nesting),
kept with any crash the fuzzers find as regression inputs for tests/it/io.rs::fuzz_regressions.
Run from this directory: python3 make_adversarial.py"""
import struct

U64MAX = 2**64 - 1
A41 = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
A22 = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
B41 = b"$MeshFormat\n4.1 1 8\n" + struct.pack("<i", 1) + b"\n$EndMeshFormat\n"
B22 = b"$MeshFormat\n2.2 1 8\n" + struct.pack("<i", 1) + b"\n$EndMeshFormat\n"

files = {
    # Counts that would allocate exabytes if trusted.
    "huge_counts_41_ascii.msh": A41
    + f"$Nodes\n1 {U64MAX} 1 {U64MAX}\n2 1 0 {U64MAX}\n1\n0 0 0\n$EndNodes\n",
    "huge_counts_41_bin.msh": B41
    + b"$Nodes\n"
    + struct.pack("<QQQQ", 1, U64MAX, 1, U64MAX)
    + struct.pack("<iiiQ", 2, 1, 0, U64MAX)
    + b"\n$EndNodes\n",
    "huge_counts_22_bin.msh": B22 + f"$Nodes\n{U64MAX}\n".encode() + b"\0" * 28 + b"\n$EndNodes\n",
    "huge_element_group_22_bin.msh": B22
    + b"$Nodes\n3\n"
    + b"".join(struct.pack("<iddd", i + 1, x, y, 0.0) for i, (x, y) in enumerate([(0, 0), (1, 0), (0, 1)]))
    + b"\n$EndNodes\n$Elements\n2147483647\n"
    + struct.pack("<iii", 2, 2147483647, 2)
    + struct.pack("<iiiiii", 1, 1, 1, 1, 2, 3)
    + b"\n$EndElements\n",
    "unknown_element_type_41_bin.msh": B41
    + b"$Nodes\n"
    + struct.pack("<QQQQ", 1, 1, 1, 1)
    + struct.pack("<iiiQ", 2, 1, 0, 1)
    + struct.pack("<Q", 1)
    + struct.pack("<ddd", 0, 0, 0)
    + b"\n$EndNodes\n$Elements\n"
    + struct.pack("<QQQQ", 1, 1, 1, 1)
    + struct.pack("<iiiQ", 2, 1, 999, 1)
    + struct.pack("<QQ", 1, 1)
    + b"\n$EndElements\n",
    # Extreme node tags: the dense tag map must not be sized by them.
    "extreme_tags_22_ascii.msh": A22
    + f"$Nodes\n3\n{U64MAX} 0 0 0\n4096 1 0 0\n1 0 1 0\n$EndNodes\n"
    + f"$Elements\n1\n1 2 2 1 1 {U64MAX} 4096 1\n$EndElements\n",
    "negative_tag_22_ascii.msh": A22 + "$Nodes\n1\n-1 0 0 0\n$EndNodes\n",
    "many_element_tags_22_ascii.msh": A22
    + "$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n$Elements\n1\n1 2 100 "
    + " ".join(["7"] * 100)
    + " 1 2 3\n$EndElements\n",
    # Sections in the wrong order or nested.
    "elements_before_nodes.msh": A41 + "$Elements\n0 0 0 0\n$EndElements\n",
    "nested_sections.msh": A22 + "$Nodes\n1\n$Elements\n$EndNodes\n",
    "end_without_section.msh": A22 + "$EndNodes\n",
    "unclosed_unknown_section.msh": A22 + "$Comments\nno end here\n",
}

for name, content in files.items():
    with open(name, "wb") as f:
        f.write(content.encode() if isinstance(content, str) else content)
