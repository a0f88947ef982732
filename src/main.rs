fn main() {
    println!("urdf-inertia");
}
