//! The CSV scene as a rapier3d world: bouncy frictionless balls in a box of six thick walls.

use crate::scene::Sphere;
use rapier3d::prelude::*;

pub struct World {
    pub params: IntegrationParameters,
    pipeline: PhysicsPipeline,
    islands: IslandManager,
    broad_phase: BroadPhaseBvh,
    narrow_phase: NarrowPhase,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    soft_bodies: SoftBodySet,
    ccd_solver: CCDSolver,
    balls: Vec<(RigidBodyHandle, f64, f64)>,
}

fn v3(a: [f64; 3]) -> Vector {
    Vector::new(a[0] as Real, a[1] as Real, a[2] as Real)
}

impl World {
    pub fn new(
        spheres: &[Sphere],
        box_len: f64,
        dt: f64,
        ccd: bool,
        length_unit: f64,
        threads: usize,
    ) -> Result<World, String> {
        let params = IntegrationParameters {
            dt: dt as Real,
            length_unit: length_unit as Real,
            // The default 400 m/s cap would clip fast projectiles and so change the energy.
            normalized_max_linear_velocity: Real::MAX,
            ..IntegrationParameters::default()
        };
        let mut bodies = RigidBodySet::new();
        let mut colliders = ColliderSet::new();
        let mut balls = Vec::with_capacity(spheres.len());
        for s in spheres {
            let body = RigidBodyBuilder::dynamic()
                .translation(v3(s.pos))
                .linvel(v3(s.vel))
                .linear_damping(0.0)
                .angular_damping(0.0)
                .can_sleep(false)
                .lock_rotations()
                .ccd_enabled(ccd)
                .build();
            let handle = bodies.insert(body);
            let ball = ColliderBuilder::ball(s.radius as Real)
                .restitution(1.0)
                .restitution_combine_rule(CoefficientCombineRule::Max)
                .friction(0.0)
                .friction_combine_rule(CoefficientCombineRule::Min)
                // The CSV's mass, not a density: the body's mass is checked after set-up.
                .mass(s.mass as Real)
                .build();
            colliders.insert_with_parent(ball, handle, &mut bodies);
            balls.push((handle, s.radius, s.mass));
        }
        // Walls one box length thick, overlapping at the edges, so nothing slips out at a corner.
        let (l, t) = (box_len as Real, box_len as Real);
        let half = [t / 2.0, l / 2.0 + t, l / 2.0 + t];
        for axis in 0..3 {
            for side in [-t / 2.0, l + t / 2.0] {
                let mut centre = [l / 2.0; 3];
                centre[axis] = side;
                let mut he = [half[1]; 3];
                he[axis] = half[0];
                let wall = ColliderBuilder::cuboid(he[0], he[1], he[2])
                    .translation(Vector::new(centre[0], centre[1], centre[2]))
                    .restitution(1.0)
                    .restitution_combine_rule(CoefficientCombineRule::Max)
                    .friction(0.0)
                    .friction_combine_rule(CoefficientCombineRule::Min)
                    .build();
                colliders.insert(wall);
            }
        }
        let mut w = World {
            params,
            pipeline: PhysicsPipeline::new(),
            islands: IslandManager::new(),
            broad_phase: BroadPhaseBvh::new(),
            narrow_phase: NarrowPhase::new(),
            bodies,
            colliders,
            impulse_joints: ImpulseJointSet::new(),
            multibody_joints: MultibodyJointSet::new(),
            soft_bodies: SoftBodySet::new(),
            ccd_solver: CCDSolver::new(),
            balls,
        };
        #[cfg(feature = "parallel")]
        w.use_threads(threads)?;
        #[cfg(not(feature = "parallel"))]
        if threads > 1 {
            return Err("--threads > 1 needs the `parallel` feature".into());
        }
        // A zero-dt step applies the insertions (mass properties, broad phase) without moving
        // anything, so neither the mass check nor the timed loop pays for set-up.
        let dt = w.params.dt;
        w.params.dt = 0.0;
        w.step();
        w.params.dt = dt;
        Ok(w)
    }

    /// Runs the pipeline's parallel parts on a dedicated rayon pool of `k` named threads.
    /// Before the first step, or rapier would start rayon's global pool (unnamed threads).
    #[cfg(feature = "parallel")]
    fn use_threads(&mut self, k: usize) -> Result<(), String> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(k)
            .thread_name(|i| format!("rapier-{i}"))
            .build()
            .map_err(|e| format!("cannot start {k} rayon threads: {e}"))?;
        self.pipeline
            .set_thread_pool(Some(std::sync::Arc::new(pool)));
        Ok(())
    }

    pub fn step(&mut self) {
        self.pipeline.step(
            Vector::ZERO,
            &self.params,
            &mut self.islands,
            &mut self.broad_phase,
            &mut self.narrow_phase,
            &mut self.bodies,
            &mut self.colliders,
            &mut self.impulse_joints,
            &mut self.multibody_joints,
            &mut self.soft_bodies,
            &mut self.ccd_solver,
            &(),
            &(),
        );
    }

    /// Largest relative difference between a body's mass in rapier and the CSV's.
    pub fn mass_err_rel(&self) -> f64 {
        self.balls
            .iter()
            .map(|&(h, _, m)| (self.bodies[h].mass() as f64 - m).abs() / m)
            .fold(0.0, f64::max)
    }

    /// The state in f64, with the CSV's radius and mass (rapier stores f32).
    pub fn spheres(&self) -> Vec<Sphere> {
        self.balls
            .iter()
            .map(|&(h, radius, mass)| {
                let b = &self.bodies[h];
                let (p, v) = (b.translation(), b.linvel());
                Sphere {
                    pos: [p.x as f64, p.y as f64, p.z as f64],
                    vel: [v.x as f64, v.y as f64, v.z as f64],
                    radius,
                    mass,
                }
            })
            .collect()
    }

    /// Kinetic energy without building the sphere list (sampled every step).
    pub fn kinetic_energy(&self) -> f64 {
        self.balls
            .iter()
            .map(|&(h, _, m)| {
                let v = self.bodies[h].linvel();
                0.5 * m
                    * [v.x, v.y, v.z]
                        .map(|c| c as f64 * c as f64)
                        .iter()
                        .sum::<f64>()
            })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball(x: f64, vx: f64) -> Sphere {
        Sphere {
            pos: [x, 0.5, 0.5],
            vel: [vx, 0.0, 0.0],
            radius: 0.05,
            mass: 0.3,
        }
    }

    #[test]
    fn head_on_pair_swaps_velocities_and_walls_reflect() {
        // Two equal balls 0.1 apart closing at 0.2 per second, then each meets a wall.
        let s = [ball(0.4, 0.1), ball(0.6, -0.1)];
        let mut w = World::new(&s, 1.0, 0.01, false, 0.1, 1).unwrap();
        assert!(w.mass_err_rel() < 1e-6);
        for _ in 0..100 {
            w.step();
        }
        // After the pair collision (t ~ 0.5 s) ball 0 moves left, ball 1 right.
        let mid = w.spheres();
        assert!((mid[0].vel[0] + 0.1).abs() < 1e-3, "{:?}", mid[0].vel);
        assert!((mid[1].vel[0] - 0.1).abs() < 1e-3, "{:?}", mid[1].vel);
        for _ in 0..500 {
            w.step();
        }
        // By t = 6 s both have bounced off their wall (at t ~ 4 s) and head back in.
        let end = w.spheres();
        assert!((end[0].vel[0] - 0.1).abs() < 1e-3, "{:?}", end[0].vel);
        assert!((end[1].vel[0] + 0.1).abs() < 1e-3, "{:?}", end[1].vel);
        // No spin, no sideways drift, no friction loss.
        assert!(
            end.iter()
                .all(|s| s.vel[1].abs() < 1e-6 && s.vel[2].abs() < 1e-6)
        );
        let (e0, e1) = (crate::metrics::kinetic_energy(&s), w.kinetic_energy());
        assert!((e1 - e0).abs() / e0 < 1e-3, "energy {e0} -> {e1}");
        assert_eq!(crate::metrics::escaped(&end, 1.0), 0);
    }
}
