"""All inverse-kinematics solutions of 6-joint serial arms (closed forms and the general 6R)."""
