// The PuzzleBot's motor board as a rosserial node (Arduino Mega / ESP32 with rosserial_arduino).
//
// The interface the host (ninjemys' rosserial_python serial_node.py, at 115200 baud) sees:
//   subscribes  cmd_vel   geometry_msgs/Twist    linear.x (m/s), angular.z (rad/s)
//               led       std_msgs/ColorRGBA     the LED ring's colour (r, g, b in 0..1; a = brightness)
//   publishes   wl, wr    std_msgs/Float32       left and right wheel speeds (rad/s) at 50 Hz
//   parameters  wheel_radius (m), wheel_base (m)    asked of the host at start-up (RequestParam)
//   logs        "puzzlebot_base ready" on /rosout once the parameters are in
// The wheel speed loop runs on the board: encoder counts -> rad/s, a PI controller per wheel
// driving the H-bridge PWM towards the speeds cmd_vel asks for. A command older than 0.5 s stops
// the motors (a lost link must not leave the robot driving).
#include <ros.h>
#include <geometry_msgs/Twist.h>
#include <std_msgs/ColorRGBA.h>
#include <std_msgs/Float32.h>

// pins: encoders on interrupt pins, H-bridge PWM and direction; the LED ring on one data pin
const int ENC_L_A = 2, ENC_L_B = 4, ENC_R_A = 3, ENC_R_B = 5;
const int PWM_L = 6, DIR_L = 7, PWM_R = 9, DIR_R = 8, LED_PIN = 11;
const float COUNTS_PER_REV = 34.0 * 12.0;  // gearbox ratio x encoder counts per motor turn

ros::NodeHandle nh;
std_msgs::Float32 wl_msg, wr_msg;
ros::Publisher wl_pub("wl", &wl_msg), wr_pub("wr", &wr_msg);

volatile long counts_l = 0, counts_r = 0;
float wheel_radius = 0.05, wheel_base = 0.19;
float target_l = 0, target_r = 0, integral_l = 0, integral_r = 0;
unsigned long last_cmd_ms = 0, last_loop_ms = 0;

void on_cmd_vel(const geometry_msgs::Twist& msg) {
  // the unicycle model, inverted: wheel angular speeds for (v, w)
  target_r = (msg.linear.x + msg.angular.z * wheel_base / 2.0) / wheel_radius;
  target_l = (msg.linear.x - msg.angular.z * wheel_base / 2.0) / wheel_radius;
  last_cmd_ms = millis();
}

void on_led_ring(const std_msgs::ColorRGBA& c) {
  analogWrite(LED_PIN, (int)(255 * c.a));  // one brightness channel on this board; RGB rings use a library
}

ros::Subscriber<geometry_msgs::Twist> cmd_sub("cmd_vel", &on_cmd_vel);
ros::Subscriber<std_msgs::ColorRGBA> led_sub("led", &on_led_ring);

void isr_left() { counts_l += digitalRead(ENC_L_B) ? -1 : 1; }
void isr_right() { counts_r += digitalRead(ENC_R_B) ? 1 : -1; }

void drive(int pwm_pin, int dir_pin, float u) {
  digitalWrite(dir_pin, u >= 0 ? HIGH : LOW);
  analogWrite(pwm_pin, (int)min(255.0f, fabs(u)));
}

void setup() {
  pinMode(ENC_L_B, INPUT_PULLUP); pinMode(ENC_R_B, INPUT_PULLUP);
  attachInterrupt(digitalPinToInterrupt(ENC_L_A), isr_left, RISING);
  attachInterrupt(digitalPinToInterrupt(ENC_R_A), isr_right, RISING);
  pinMode(PWM_L, OUTPUT); pinMode(DIR_L, OUTPUT); pinMode(PWM_R, OUTPUT); pinMode(DIR_R, OUTPUT);
  nh.getHardware()->setBaud(115200);
  nh.initNode();
  nh.advertise(wl_pub); nh.advertise(wr_pub);
  nh.subscribe(cmd_sub); nh.subscribe(led_sub);
  while (!nh.connected()) nh.spinOnce();
  nh.getParam("wheel_radius", &wheel_radius);
  nh.getParam("wheel_base", &wheel_base);
  nh.loginfo("puzzlebot_base ready");
}

void loop() {
  unsigned long now = millis();
  if (now - last_loop_ms >= 20) {  // 50 Hz
    float dt = (now - last_loop_ms) / 1000.0;
    last_loop_ms = now;
    noInterrupts(); long cl = counts_l, cr = counts_r; counts_l = counts_r = 0; interrupts();
    wl_msg.data = 2 * PI * cl / COUNTS_PER_REV / dt;
    wr_msg.data = 2 * PI * cr / COUNTS_PER_REV / dt;
    wl_pub.publish(&wl_msg); wr_pub.publish(&wr_msg);
    if (now - last_cmd_ms > 500) { target_l = target_r = 0; integral_l = integral_r = 0; }
    float el = target_l - wl_msg.data, er = target_r - wr_msg.data;
    integral_l += el * dt; integral_r += er * dt;
    drive(PWM_L, DIR_L, 12.0 * el + 40.0 * integral_l);
    drive(PWM_R, DIR_R, 12.0 * er + 40.0 * integral_r);
  }
  nh.spinOnce();
}
