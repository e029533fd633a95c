"""The laboratory velocity-step fit: the quasi-static spring-slider fitted with its stiffness, trend and
correlated noise (variable projection, compiled sums), and its result."""
